"""Maps over parameter grids: what one point computes (kinds) and the resumable store on
dask.distributed (store)."""
