"""Accuracy against cost: convergence families for scene kinds (`bulkflow-accuracy KIND`).

convergence.py holds the pure logic (observed order, Richardson extrapolation, GCI, the cheapest
member for a target), runs.py launches and times the solver, one module per kind defines the
family, and study.py writes the CSV/PNG/JSON. docs/accuracy.md describes the method and results.
"""
