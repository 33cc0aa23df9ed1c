"""EKF node: motion, track slip, hull submersion, traction model."""
