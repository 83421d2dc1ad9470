"""lindstedt: exact perturbation series for nonlinear oscillators, emitted as code and LaTeX.

The pipeline, a folder per group of stages and a module per stage (input -> output), in
order; a stage imports only stages above it::

    algebra.series  the one Fourier kernel: exact P(C) + S·R(C) over QQ (FLINT fmpq_poly)
                    and QQ[params] (fmpq_mpoly), the odd-cosine fast path, relaxed (online)
                    products of ε-series of Trig sums, and the Laurent form in e^{is} over
                    complex128 for the numeric methods
    algebra.resum   Padé approximants over QQ, Andersen & Geer's   [c_k] -> Resummed
                    w-variable; spurious poles, neighbour spread (past the radius)
    derive.equation  user text through a whitelist walker over ``ast``   str -> Equation
    derive.models   the oscillator registry, a user's Oscillator,  Equation, K -> Model
                    its L–P Model
    derive.orbits   where a free oscillator's family of periodic   Model -> OrbitDomain
                    orbits ends: the first integral's separatrix, to 30 digits
    derive.lindstedt  L–P series, order-by-order equations, naive  Model, K -> SeriesSolution
                    expansion; the nearest singularity and the radius of a series
    derive.cycles   the limit cycles of q'' + q = ε f(q, q'), each  SelfExcited, K -> LimitCycle
                    with its stability, exact in Q or Q(a₀)
    derive.hill     Hill's equation x'' + (δ + ε p(t))x = 0:       p(t), n, K -> curves
                    transition curves out of each tongue, a damped tongue's tip, and
                    Mathieu's a_m(q), b_m(q), exact (L–P about cos nτ, sin nτ)
    derive.averaging  the slow flow of q'' + q = ε f (+ ε F cos   Oscillator, K -> SlowFlow
                    ωt): near-identity averaging to any order in van der Pol's variables,
                    exact (R_k, Φ_k of dr/dt, dφ/dt)
    numerics.integrate  the one integrator: RK4 of any polynomial  ForceTable -> flows
                    force table, compiled; flows, sweeps with their jumps, simulations
    numerics.newton  the one Newton's method for R(x) = 0          R, J, x -> root
    numerics.floquet  Floquet multipliers: Hill about q₀, a damped  orbit -> multipliers
                    pump over a grid, the full Hill equation, the verdict
    numerics.shooting  periodic orbits by Newton on the flow map,  guess -> PeriodicOrbit
                    true folds, true limit cycles
    numerics.references  elliptic periods, cn, the pendulum, a     x -> truth
                    cycle by DOP853, Mathieu by the Hill matrix and mpmath
    analysis.driven  the notes' driven Duffing: one harmonic,      Drive -> branches
                    μ-expansion with phase, harmonic balance
    analysis.mu_exact  the μ-expansion (undamped, damped) and the  K -> exact orders
                    balance equations, exactly, for LaTeX and emission
    analysis.polynomial  a user's driven equation lowered to data, text -> DrivenEquation
                    the Galerkin balance of any polynomial force, an amplitude bound
    analysis.continuation  pseudo-arclength through folds, in ω    system -> curve
                    or in the drive amplitude from rest; crossings of a level
    analysis.response  one-harmonic curves and folds, the balance  Drive | equation,
                    continued over an ω range (the notes' and any    ω range -> folds
                    polynomial force)
    analysis.periodic  every distinct periodic orbit at one drive:  Drive | equation ->
                    seeds, balance, shooting, Floquet; the true fold  orbits
    analysis.subharmonic  orbits of n drive periods of any         equation, n, ω -> orbits
                    polynomial force: balance on the harmonics of ω, shooting, Floquet,
                    onset; the notes' eq. 10.83 in closed form
    analysis.mixing  combination tones of a multi-tone drive to    ForceTable, drives -> tones
                    the second order of any polynomial force, against a simulation
    analysis.parametric  q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³ = 0:     Pump, ω range -> branches
                    one-harmonic branches, tongue, onsets, balance, full-Hill stability
    lower.printers  NumbaPrinter(PythonCodePrinter), LaTeX         Expr -> str
                    rationals
    lower.records   the IR records (Module, Evaluator, Derivation,  -> records
                    PeriodFormula, Unit) a template lays out
    lower.forms     Horner/Estrin, the Chebyshev recurrence, AGM    Expr -> Expr
                    steps, argument guards, the scaled variable x = εA^k
    lower.series    free oscillators, limit cycles, resummations,  solution -> Module
                    Mathieu, tongues -> Module
    lower.driven    the μ-expansion's branches (Cardano), damped,   orders -> Module
                    the harmonic-balance system
    lower.documents  derivations' LaTeX records, the AGM period,   solution -> Unit
                    a chosen formula, the slow flow
    emit.render     strict Jinja2 environments, provenance,        Unit -> files
                    one-unit writes
    methods.kernels  compiled period kernels (Horner, AGM, cn),     PeriodSeries -> floats
                    the period series re-expanded, each method's coefficients
    methods.references  the references each method is checked      x -> truth
                    against (mpmath, quadrature, shooting, the driven modules on a grid)
    methods.verify  resummations verified on a grid before they    series -> Resummed
                    are emitted (limit cycles, Mathieu, Hill tongues)
    methods.targets  what generate derives and lowers per target   Request -> Unit
    methods.registry  the method registry: per method what it      Model | Drive -> Method
                    applies to (and why not), how it derives, evaluates, lowers, its
                    reference
    compiler        derive -> lower -> render -> write, each once  Target, Request -> files
    choose          methods × orders, verified error, recorded     tol, range -> Choice
                    cost model
    sweep.kinds     what one point of a map computes: the notes'   point -> fields
                    kinds, and any equation's parameters as axes
    sweep.store     grids in blocks on dask.distributed, into a    kind, axes -> Dataset
                    resumable Zarr store
    charts          matplotlib figures                             results -> PNG/SVG/PDF
    costs           each command's estimated wall time and bounds  arguments -> Cost
    cli.common      what every command shares: light constants,   argv -> Namespace
                    argument types and flags, the report shape
    cli.series      series, mathieu, tongues, slowflow, models,     records -> JSON, tables
                    generate
    cli.driven      driven, response, subharmonic, parametric,      records -> JSON, tables
                    mixing
    cli.choose      choose, clock, scene                            Choice -> JSON, tables
    cli.sweep       sweep                                          Dataset -> summary
    cli.demo        the demo                                       -> out/
    cli             the COMMANDS table: parser, cost guard, --help  argv -> exit status
                    (each command imports its stages itself)

Each folder's ``__init__`` holds its docstring only.  Beside the stages: ``errors`` (the
one-line InputError), ``limits`` (every bound, and the one integer-range check) and
``display`` (Jupyter's LaTeX and HTML reprs), which import no stage.
"""

__version__ = "0.1.0"
