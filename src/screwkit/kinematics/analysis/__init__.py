"""What is computed on a solved motion: coupler curves, transmission, limit positions and dwells, sensitivities, loop mobility (docs/architecture.md)."""
