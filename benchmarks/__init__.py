"""Benchmarks: timings and force-call counts, printed as ratios. Run ``make bench``."""
