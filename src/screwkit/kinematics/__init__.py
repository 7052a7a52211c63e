"""Position, velocity and acceleration analysis of single closed loops."""
