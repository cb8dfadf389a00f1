"""Where the work runs: atomic file writes, the process pool and a dask cluster. Imports nothing
of balpipe's computation."""
