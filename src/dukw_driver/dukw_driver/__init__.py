"""Hardware nodes: servo switch (RC mux), motor controllers, IMU/DGPS, water sensors."""
