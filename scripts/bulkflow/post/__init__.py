"""Post-processing of bulkflow output files (CSV histories, HDF5 frames)."""
