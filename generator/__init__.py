"""lindstedt: exact perturbation series for nonlinear oscillators, emitted as code and LaTeX.

The pipeline, one module per stage (input -> output); a stage imports only stages above it::

    equation   user text through a whitelist walker over ``ast``         str -> Equation
    models     the oscillator registry, a user's Oscillator, its L–P Model  Equation, K -> Model
    orbits     where a free oscillator's family of periodic orbits ends:  Model -> OrbitDomain
               the first integral's separatrix, to 30 digits
    series     the one Fourier kernel: exact P(C) + S·R(C) over QQ       (FLINT fmpq_poly) and
               QQ[params] (fmpq_mpoly), the odd-cosine fast path, relaxed (online) products
               of ε-series of Trig sums, and the Laurent form in e^{is} over complex128 for the
               numeric methods
    lindstedt  L–P series, order-by-order equations, naive expansion    Model, K -> SeriesSolution
               and the limit cycles of q'' + q = ε f(q, q')             SelfExcited, K -> LimitCycle
    hill       Hill's equation x'' + (δ + ε p(t))x = 0: transition      p(t), n, K -> curves
               curves out of each tongue, a damped tongue's tip, and
               Mathieu's a_m(q), b_m(q), exact (L–P about cos nτ, sin nτ)
    averaging  the slow flow of q'' + q = ε f (+ ε F cos ωt): near-     Oscillator, K -> SlowFlow
               identity averaging to any order in van der Pol's
               variables, exact (R_k, Φ_k of dr/dt, dφ/dt)
    resum      Padé approximants over QQ, Andersen & Geer's w-variable; [c_k] -> Resummed
               spurious poles, neighbour spread (past the radius)
    numerics   references: elliptic periods, Jacobi cn; one RK4 step for any polynomial force
               table: shooting + Floquet, sweeps, true folds, simulations
    driven     μ-expansion with phase, harmonic balance (Duffing; and a  Drive | equation ->
               user's polynomial force by alternating frequency/time)   branches
    response   one-harmonic curves and folds, balance continuation in   Drive | equation,
               ω or in the drive; every periodic orbit at one drive     ω range -> folds
    subharmonic  orbits of n drive periods of any polynomial force:     equation, n, ω ->
               balance on the harmonics of ω, shooting, Floquet, onset; orbits
               the notes' eq. 10.83 in closed form
    mixing     combination tones of a multi-tone drive to the second    ForceTable, drives
               order of any polynomial force, against a simulation      -> tones
    parametric  q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³ = 0: one-harmonic     Pump, ω range ->
                branches, tongue, onsets, balance, full-Hill stability branches
    printers   NumbaPrinter(PythonCodePrinter), LaTeX rationals         Expr -> str
    lower      solutions -> IR records (Module, Evaluator, Derivation,  solution -> Unit
               PeriodFormula); Horner, Chebyshev recurrence, AGM steps
    emit       strict Jinja2 environments, provenance, one-unit writes  Unit -> files
    methods    the method registry: per method what it applies to (and  Model | Drive -> Method
               why not), how it derives, evaluates, lowers, its reference
    compiler   derive -> lower -> render -> write, each once, in order  Target, Request -> files
    choose     methods × orders, verified error, recorded cost model    tol, range -> Choice
    sweep      driven maps over grids on dask.distributed, into Zarr    kind, axes -> Dataset
    charts     matplotlib figures                                       results -> PNG/SVG/PDF
    costs      each command's estimated wall time and bounds            arguments -> Cost
    cli        the command line (each command imports its stages itself)

Beside the stages: ``errors`` (the one-line InputError) and ``display`` (Jupyter's LaTeX and
HTML reprs), which import no stage.
"""

__version__ = "0.1.0"
