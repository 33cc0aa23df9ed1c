"""Shared pieces of the DUKW-Ling stack: configuration loading (ROS-free) and thin rclpy helpers."""
