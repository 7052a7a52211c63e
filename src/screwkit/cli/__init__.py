"""The ``screwkit`` command line."""
