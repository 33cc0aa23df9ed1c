"""Mode manager and differential-drive controller with the vehicle's limits."""
