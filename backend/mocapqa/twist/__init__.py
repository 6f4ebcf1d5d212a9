"""twist."""
