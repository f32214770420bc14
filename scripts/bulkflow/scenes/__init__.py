"""Parametric scene generators: they write plain Abaqus input files (.inp) for bulkflow."""
