"""Shared pieces of the DUKW-Ling stack: ROS-free configuration loading, thin rclpy helpers."""
