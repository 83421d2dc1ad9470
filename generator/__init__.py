"""lindstedt: exact perturbation series for nonlinear oscillators, emitted as code and LaTeX.

The pipeline, one module per stage (input -> output)::

    models     oscillator definitions (frozen dataclasses)           -> Model
    series     exact Fourier algebra in the monomial basis of cos s  (the fast kernel)
    lindstedt  L–P series, order-by-order equations, naive expansion Model, order -> SeriesSolution
    driven     μ-expansion with phase, harmonic balance          Drive, order -> branches
    response   one-harmonic curves and folds, balance continuation  Drive, ω range -> folds
    choose     methods × orders, verified error and measured cost    tol, range -> Choice
    numerics   references: elliptic periods, Jacobi cn, shooting + Floquet, sweeps, true folds
    sweep      grids of driven maps on dask.distributed into resumable Zarr  kind, axes -> Dataset
    lower      solutions -> IR records (Evaluator, Module)           Horner, Chebyshev recurrence
    printers   NumbaPrinter(PythonCodePrinter), LaTeX rationals      Expr -> str
    emit       strict Jinja2 environments, provenance, atomic writes IR -> files in generated/
    charts     matplotlib figures                                results -> PNG/SVG/PDF
    cli        the command line
"""

__version__ = "0.1.0"
