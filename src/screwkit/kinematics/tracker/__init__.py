"""The generic single-loop solver: the loop-closure map, Newton, the continuation tracker and its fill, the motion build, rates, idle spins and singular samples (docs/architecture.md)."""
