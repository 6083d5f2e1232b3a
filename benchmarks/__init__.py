"""Speed-against-error and scaling measurements (run as python -m benchmarks.NAME)."""
