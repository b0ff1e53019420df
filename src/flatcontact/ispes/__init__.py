"""ISPES scans: the grid contract, one relaxation per point, the resumable store, executors."""
