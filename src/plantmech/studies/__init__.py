"""Design studies: tolerance Monte Carlo, parameter sweeps and multi-start optimization,
run in chunks on Dask with results streamed to Parquet (docs/studies.md)."""
