"""Closed-loop flight simulation: quadrotor model, outer-loop controllers, disturbances."""
