"""lindstedt: exact perturbation series for nonlinear oscillators, emitted as code and LaTeX.

The pipeline, one module per stage (input -> output)::

    models     oscillator definitions                      -> Model
    series     exact Fourier-series algebra over QQ / QQ[params] (the fast kernel)
    lindstedt  L–P series and the naive expansion          Model, order -> SeriesSolution
    cli        the command line                            arguments -> tables, JSON
"""

__version__ = "0.1.0"
