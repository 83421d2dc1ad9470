"""lindstedt: exact perturbation series for nonlinear oscillators, emitted as code and LaTeX.

The pipeline, a folder per group of stages and a module per stage [input -> output], in
order; a stage imports only stages above it::

    algebra.series          the one Fourier kernel: exact P(C) + S·R(C) over QQ (FLINT
                            fmpq_poly), a number field Q(θ) (fmpq_poly parts) and QQ[params]
                            (fmpq_mpoly), the odd-cosine fast path, the Laurent form in
                            e^{is} over complex128 for the numeric methods
                            [coefficients -> Trig]
    algebra.lazy            the one lazy-series engine: coefficients on demand, each once —
                            terms, maps, sums, Cauchy products, the relaxed (online, packed)
                            product of ε-series of Trig sums [series -> coefficient i]
    algebra.resum           the one power-series toolkit (product, reciprocal, square root,
                            binomial series, composition; Horner exact and in floats, partial
                            sums; the nearest singularity and the radius), Padé approximants
                            over QQ, Andersen & Geer's w-variable; spurious poles, neighbour
                            spread (past the radius) [[c_k] -> Resummed]
    derive.equation         user text through a whitelist walker over ``ast`` [str -> Equation]
    derive.models           the oscillator registry, a user's Oscillator, its L–P Model
                            [Equation, K -> Model]
    derive.problem          the one problem record: a text (one equation, a system of any
                            n, a preset's name) as its equations, read once; a command's
                            route to a method asks it [str -> Problem]
    derive.orbits           where a free oscillator's family of periodic orbits ends: the first
                            integral's separatrix, to 30 digits [Model -> OrbitDomain]
    derive.lindstedt        L–P series, order-by-order equations, naive expansion
                            [Model, K -> SeriesSolution]
    derive.cycles           the limit cycles of q'' + q = ε f(q, q'), each with its stability,
                            exact in Q or Q(a₀) [SelfExcited, K -> LimitCycle]
    derive.hill             Hill's equation x'' + (δ + ε p(t))x = 0: transition curves out of
                            each tongue, a damped tongue's tip, Mathieu's a_m(q), b_m(q), exact
                            (L–P about cos nτ, sin nτ) [p(t), n, K -> curves]
    derive.system           a system of coupled oscillators from text: mass, damping,
                            stiffness, force, drive, the linear modes' exact ω₀², the power-
                            balance bound on a driven one's orbits [str -> System]
    derive.nnm              nonlinear normal modes as exact L–P series in Q or Q(ω₀²), the
                            secular condition by the left null vector, internal resonances
                            refused [System, mode, K -> NormalModeSeries]
    derive.resonance        a system's modes in internal resonance, named, their shapes; of
                            their slow flow the coupled modes and how weak the nonlinearity
                            is [System -> modes]
    derive.ssm_exact        a spectral submanifold's normal form exactly in Q(λ, λ̄) (rational
                            data, n ≤ 3), the floating-point ground's check
                            [System, mode, K -> ExactSSM]
    derive.averaging        the slow flow of q'' + q = ε f (+ ε F cos ωt) and of a system's
                            modes in internal resonance: near-identity averaging over one
                            angle in van der Pol's variables, to any order (a system: the
                            first), exact (R_k, Φ_k of each mode's da/dt, dφ/dt)
                            [Oscillator | System, K -> SlowFlow]
    numerics.integrate      the one integrator: RK4 of any polynomial force table, compiled;
                            flows, sweeps with their jumps, simulations; a system's polynomial
                            force and its compiled field [ForceTable | PolynomialField -> flows]
    numerics.newton         the one Newton's method for R(x) = 0 and its bordered, secant and
                            safeguarded variants [(R, J), x -> root]
    numerics.floquet        Floquet multipliers: Hill about q₀, a damped pump over a grid, the
                            full Hill equation, a system's variational monodromy about many
                            orbits at once, the verdict [orbit -> multipliers]
    numerics.shooting       periodic orbits by Newton on the flow map, true folds, true limit
                            cycles, a driven system's orbit (DOP853) [guess -> PeriodicOrbit]
    numerics.references     elliptic periods, cn, the pendulum, a cycle by DOP853, Mathieu by
                            the Hill matrix and mpmath [x -> truth]
    analysis.polynomial     a user's driven equation lowered to data, the Galerkin balance of
                            any polynomial force of one or more coordinates, an amplitude bound
                            [text -> DrivenEquation, PolynomialBalance]
    analysis.driven         the notes' driven Duffing: one harmonic, μ-expansion with phase,
                            harmonic balance [Drive -> branches]
    analysis.mu_exact       the μ-expansion (undamped, damped) and the balance equations,
                            exactly, for LaTeX and emission [K -> exact orders]
    analysis.continuation   pseudo-arclength through folds, in ω or in the drive amplitude from
                            rest; crossings of a level; where a branch is born (the one Onset:
                            a drive amplitude, a tongue's edge) [system -> curve]
    analysis.attractors     along every traced branch: folds, period doublings, Neimark–Sacker
                            points (refined by secant on |μ| − 1); where no period-1 orbit is
                            stable or one loses stability by Neimark–Sacker, the attractor a
                            simulation settles on (period-k, quasi-periodic, chaotic), its
                            spectral lines and ranges [branches, multipliers -> Dynamics]
    analysis.response       one equation's one-harmonic balance of any polynomial force: its
                            amplitudes, its folds (a resultant, exact), the ω range, the seeds
                            [equation, ω range -> folds, range]
    analysis.systems        the response of n ≥ 1 coordinates: every branch of the balance
                            continued in ω, sought at the ends and probes (one-harmonic roots,
                            the drive from rest, the backbones), Floquet verdicts, folds,
                            jumps; true folds and sweeps, or shooting checks
                            [equation | System, ω range -> Response]
    analysis.ssm            the spectral submanifold of one mode of a damped system, by the
                            parametrisation method in normal-form style, in floating point
                            with sparse matrices: reduced dynamics, backbone, damping ratio,
                            physical amplitudes [System, mode, K -> SSM]
    analysis.ssm_forced     its forced response: the non-autonomous SSM at first order in the
                            drive and every order in p, every steady state (a resultant's
                            roots), stability, folds, peaks; what ssm reports
                            [SSM, ω range -> ForcedResponse, Reduction]
    analysis.ssm_resonant   the 4-D SSM of two modes in near 1:1, 1:2 or 1:3 internal
                            resonance: multi-index homological equations bordered per resonant
                            direction, the reduced dynamics in normal form and polar form
                            (ρ₁, ρ₂, ψ = θ₂ − rθ₁), the slow flow's variables
                            [System, (M1, M2), K -> ResonantSSM]
    analysis.ssm_resonant_forced  its forced response (the drive at leading order, the
                            steady states continued in ω, stability, amplitudes) and what
                            ssm --mode M1,M2 reports [ResonantSSM, ω range -> ResonantReduction]
    analysis.periodic       every distinct periodic orbit at one drive: seeds, balance,
                            shooting, Floquet; the report of `driven`
                            [Drive | equation -> orbits]
    analysis.subharmonic    orbits of n drive periods of any polynomial force: balance on the
                            harmonics of ω, shooting, Floquet, onset; the notes' eq. 10.83 in
                            closed form [equation, n, ω -> orbits]
    analysis.mixing         combination tones of a multi-tone drive to the second order of any
                            polynomial force, against a simulation [ForceTable, drives -> tones]
    analysis.parametric     q̈ + 2ζq̇ + (1 + ε cos 2ωt)q + γq³ = 0: one-harmonic branches,
                            tongue, onsets, balance, full-Hill stability
                            [Pump, ω range -> branches]
    analysis.curves         the curves a command draws and writes as CSV, sampled once: a free
                            oscillator's ω, T across its validity, a limit cycle's amplitude
                            and ω against ε, a slow flow's portrait, a normal mode's backbone
                            [series | SlowFlow -> SeriesCurves, CycleCurves, Portrait, Backbone]
    lower.printers          NumbaPrinter(PythonCodePrinter), LaTeX rationals, a series'
                            validity in words [Expr -> str]
    lower.records           the IR records (Module, Evaluator, SeriesTables, SeriesDerivation,
                            PeriodFormula, Unit) a template lays out [-> records]
    lower.forms             Horner/Estrin, the Chebyshev recurrence, AGM steps, argument guards,
                            the scaled variable x = εA^k [Expr -> Expr]
    lower.series            a family of periodic orbits of any number of coordinates (a free
                            oscillator, a normal mode: ω, T, the motion, the error's bound,
                            NaN outside its orbits and radius), limit cycles, resummations,
                            Mathieu, tongues [solution -> Module]
    lower.driven            the μ-expansion's branches (Cardano), damped, the harmonic-balance
                            system [orders -> Module]
    lower.ssm               an SSM's reduced model as numbers: γ_j, the radius, the outputs'
                            harmonics, the forced terms on Chebyshev nodes
                            [Reduction -> ReducedModule]
    lower.documents         the derivations' LaTeX records, the AGM period, a chosen formula,
                            the slow flow [solution -> Unit]
    emit.render             strict Jinja2 environments, provenance, one-unit writes
                            [Unit -> files]
    methods.kernels         compiled period kernels (Horner, AGM, cn), the period series re-
                            expanded, each method's coefficients [PeriodSeries -> floats]
    methods.references      the references each method is checked against (mpmath, quadrature,
                            shooting, the driven modules on a grid) [x -> truth]
    methods.verify          resummations verified on a grid before they are emitted (limit
                            cycles, Mathieu, Hill tongues) [series -> Resummed]
    methods.targets         what generate derives and lowers per target [Request -> Unit]
    methods.registry        the method registry: per method what it applies to (and why not),
                            how it derives, evaluates, lowers, its reference
                            [Model | Drive -> Method]
    compiler                derive -> lower -> render -> write, each once, in order
                            [Target, Request -> files]
    choose                  methods × orders, verified error, recorded cost model
                            [tol, range -> Choice]
    sweep.cores             the cores a local sweep may use (CPU affinity) [-> int]
    sweep.kinds             what one point of a map computes: the notes' kinds, and any
                            equation's or driven system's parameters as axes [point -> fields]
    sweep.store             grids in blocks on dask.distributed, into a resumable Zarr store
                            [kind, axes -> Dataset]
    charts                  matplotlib figures, the response of any number of coordinates
                            among them [results -> PNG/SVG/PDF]
    charts_modes            the frequency–energy plot of a system's normal modes: backbones
                            from the series beside shot orbits; a resonant system's energy
                            exchange; an SSM's backbone, damping and forced response
                            [System | ssm JSON -> PNG/SVG/PDF]
    charts_series           a free oscillator's ω and T against its amplitude variable with the
                            orbit edge and the radius marked; a limit cycle against ε; a slow
                            flow's phase portrait [curves -> PNG/SVG/PDF]
    costs                   each command's estimated wall time and bounds [arguments -> Cost]
    cli.common              what every command shares: light constants, argument types and
                            flags, the report shape [argv -> Namespace]
    cli.system              nnm; the JSON and table of a family of periodic orbits of any
                            number of coordinates [NormalModeSeries, SeriesSolution -> JSON,
                            tables]
    cli.ssm                 ssm of a SYSTEM or a model folder, and generate --ssm
                            [Reduction -> JSON, table, CSV, module]
    cli.series              series, mathieu, tongues, models, generate
                            [records -> JSON, tables]
    cli.slowflow            slowflow of one oscillator or of a system's resonant modes: one
                            contract, one table, the portrait or the energy exchange
                            [SlowFlow -> JSON, table, CSV]
    cli.driven              driven, subharmonic, parametric, mixing [records -> JSON, tables]
    cli.response            response of any number of coordinates [Response -> JSON, table,
                            CSV]
    cli.choose              choose, clock, scene [Choice -> JSON, tables]
    cli.sweep               sweep [Dataset -> summary]
    cli.demo                the demo [-> out/]
    cli                     the COMMANDS table: the parser, the cost guard and --help loop over
                            it (each command imports its stages itself) [argv -> exit status]

Each folder's ``__init__`` holds its docstring only.  Beside the stages: ``errors`` (the
one-line InputError), ``limits`` (every bound, and the one integer-range check) and
``display`` (Jupyter's LaTeX and HTML reprs), which import no stage.
"""

__version__ = "0.1.0"
