"""The `sediment` command line."""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np

from . import _core
from .readout import SCHEDULES as SCHEDULE_NAMES


def finite(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got '{text}'") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be finite, got {text}")
    return value


def positive(text: str) -> float:
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be > 0, got {text}")
    return value


def nonnegative(text: str) -> float:
    value = finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"must be >= 0, got {text}")
    return value


def count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a whole number, got '{text}'") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be >= 1, got {text}")
    return value


def cmd_terminal(args: argparse.Namespace) -> int:
    speed, regime = _core.terminal_velocity(args.law, args.fluid_density, args.viscosity, args.yield_stress,
                                            args.diameter, args.particle_density, args.gravity)
    print(f"terminal velocity: {speed:.6g} m/s ({regime})")
    if args.yield_stress == 0:
        tau = _core.relaxation_time(args.law, args.fluid_density, args.viscosity, args.diameter,
                                    args.particle_density)
        print(f"relaxation time tau = m / F'(0): {tau:.6g} s; explicit drag needs dt < {2 * tau:.3g} s")
    if speed > 0:
        t99 = _core.time_to_fraction(args.law, args.fluid_density, args.viscosity, args.yield_stress,
                                     args.diameter, args.particle_density, args.gravity, 0.99)
        print(f"time to 99 % of it from rest: {t99:.6g} s")
    if args.youngs_modulus:
        rayleigh = _core.rayleigh_time(0.5 * args.diameter, args.particle_density, args.youngs_modulus,
                                       args.poisson_ratio)
        print(f"Rayleigh time: {rayleigh:.6g} s (the 20 % rule: dt = {0.2 * rayleigh:.3g} s)")
    return 0


def cmd_case_a(args: argparse.Namespace) -> int:
    from . import sweep
    from .single_sphere import case_a_study

    result = case_a_study(args.out)
    print(sweep.table(result), end="")
    print("\n".join(sweep.summary(result, 0.01)))
    print(f"figures: {args.out / 'case_a_velocity.png'}, {args.out / 'sweep.png'}\ntable:   {args.out / 'sweep.csv'}")
    return 0


def cmd_sample(args: argparse.Namespace) -> int:
    from .psd import read_psd
    from .readout import Fluid
    from .sample import Cylinder, Effects, describe, plan, write

    cylinder = Cylinder.bravo() if args.cylinder == "bravo" else Cylinder()
    if args.height is not None:
        cylinder = Cylinder(cylinder.area, args.height)
    scene = plan(read_psd(args.psd), geometry=args.geometry, cylinder=cylinder, mass=args.mass,
                 fluid=Fluid(particle_density=args.particle_density), width=args.width, classes=args.classes,
                 particles=None if args.real_grains else args.particles,
                 effects=Effects(args.law, args.hindered, args.contacts, args.lubrication),
                 layers=args.layers, t_end=args.t_end, courant=args.courant, seed=args.seed)
    print(describe(scene))
    for path in write(scene, args.out):
        print(f"wrote {path}")
    print(f"next: sediment run {args.out / 'in.sedimentation'}")
    return 0


def cmd_run(args: argparse.Namespace) -> int:
    from .run import run_deck

    result = run_deck(args.deck, ranks=args.np, variables=dict(args.var or []), progress=not args.quiet)
    print(f"{result.deck.name}: {result.steps} steps, {result.simulated_time:.6g} s simulated in "
          f"{result.wall_seconds:.1f} s on {args.np} rank(s); log {result.log}")
    return 0


def cmd_readout(args: argparse.Namespace) -> int:
    from .granulometry import error_summary, read_all, write_report
    from .psd import read_psd
    from .readout import Column, Fluid, Hydrometer
    from .synthetic import stokes_column

    if args.layers is not None:    # PSD tables that `sediment sample` wrote beside the run
        for option, name in (("psd", "input_psd.csv"), ("simulated", "simulated_psd.csv")):
            beside = args.layers.parent / name
            if getattr(args, option) is None and beside.is_file():
                setattr(args, option, beside)
                print(f"using {beside}")
    psd = read_psd(args.psd) if args.psd else None
    simulated = read_psd(args.simulated) if args.simulated else None
    if args.layers is not None:
        from .layers import read_layers
        column = Column.from_layers(read_layers(args.layers), surface=args.surface)
        if args.viscosity is not None:    # e.g. the lab's temperature differs from the simulation's
            column = replace(column, fluid=replace(column.fluid, viscosity=args.viscosity))
        title = f"{args.layers.parent.name}/{args.layers.name}: simulated sedimentation test"
    else:
        if psd is None:
            raise ValueError("give a layer file, or --psd with --stokes-preview for an analytic column")
        fluid = Fluid(particle_density=args.particle_density)
        times = np.concatenate([[0.0], np.geomspace(10.0, 1440 * 60.0, 400)])
        column = stokes_column(psd, args.height, times, args.concentration, fluid)
        title = f"{args.psd.name}: Stokes settling preview (no DEM)"
    instruments = ["hydrometer", "buoyancy", "pipette"] if args.instrument == "all" else [args.instrument]
    hydrometer = Hydrometer.measured(*args.hydrometer) if args.hydrometer else None
    readings, notes = read_all(column, instruments, args.schedule, args.sphere_depth, args.pipette_depth,
                               args.pipette_volume, args.cylinder_area, hydrometer)
    for note in notes:
        print(note)
    for path in write_report(readings, args.out, psd, simulated, title=title):
        print(f"wrote {path}")
    for name, reference in (("input", psd), ("simulated", simulated)):
        if reference is not None:
            for instrument, size_range, count, error in error_summary(readings, reference):
                print(f"{instrument:10s} {size_range:10s} {count:3d} readings, mean |P - {name} PSD| = {error:.2f} points")
    return 0


def cmd_calibrate(args: argparse.Namespace) -> int:
    from . import calibrate

    if args.test == "slump":
        result = calibrate.yield_stress_from_slump(args.slump, args.height, args.density)
    elif args.test == "restitution":
        result = calibrate.restitution_from_drops(args.drop, args.rebound)
    else:
        result = calibrate.friction_from_tilt(args.lift, args.length)
    print(result.describe())
    return 0


def cmd_paste(args: argparse.Namespace) -> int:
    from . import paste

    if args.study == "restitution":
        c = paste.tsuji_for_restitution(args.target)
        print(f"damping tsuji {c:.4f} gives a simulated restitution of {paste.simulated_restitution(c):.4f} "
              f"(the input {args.target} itself gives {paste.simulated_restitution(args.target):.4f})")
    elif args.study == "drop-test":
        rows = paste.drop_study(args.out)
        print(f"{'H_f [mm]':>9s} {'H_r meas.':>10s} {'H_r sim.':>9s} {'error':>7s}")
        for r in rows:
            print(f"{r.fall * 1e3:9.0f} {r.measured * 1e3:10.1f} {r.simulated * 1e3:9.2f} {r.error:+7.1%}")
        print(f"mean |error| {np.mean([abs(r.error) for r in rows]):.1%}; wrote {args.out / 'drop_test.csv'}, "
              f"{args.out / 'drop_test.png'}")
    elif args.study == "balls":
        drops = paste.ball_study(args.out)
        print(f"{'d [mm]':>6s} {'fall [mm]':>9s} {'submergence':>11s} {'depth [mm]':>10s} {'t_rest [s]':>10s} "
              f"{'creep [m]':>9s}")
        for b in drops:
            print(f"{b.diameter * 1e3:6.1f} {b.fall * 1e3:9.0f} {'partial' if b.submergence else 'step':>11s} "
                  f"{b.depth * 1e3:10.2f} {b.t_rest:10.4f} {b.creep:9.2g}")
        print(f"{sum(b.wall_seconds for b in drops):.1f} s of runs; wrote {args.out / 'ball_in_paste.csv'}, "
              f"{args.out / 'ball_in_paste.png'}")
    elif args.study == "energy":
        balance = paste.energy_balance(args.diameter, args.fall, args.dt)
        print(f"loss of potential + kinetic energy {balance.mechanical_loss:.6g} J; work of buoyancy "
              f"{balance.buoyancy_work:.6g} J, of drag and yield {balance.drag_work:.6g} J; "
              f"residual {balance.residual:+.2e} of the loss")
    else:
        from . import funnel

        pours = funnel.funnel_study(args.out, runs=args.runs, jobs=args.jobs, dt=args.dt)
        depths = np.concatenate([paste.PASTE["surface"] - p.positions[:, 2] for p in pours])
        for p in pours:
            print(f"seed {p.seed:3d}: {p.balls} of {p.placed} balls in the mould, {p.spilled} spilled, centres "
                  f"{(paste.PASTE['surface'] - p.positions[:, 2].max()) * 1e3:.1f} to "
                  f"{(paste.PASTE['surface'] - p.positions[:, 2].min()) * 1e3:.1f} mm deep, poured in "
                  f"{p.pour_time:.3f} s, {p.wall_seconds:.1f} s wall")
        print(f"all runs: centres {depths.min() * 1e3:.1f} to {depths.max() * 1e3:.1f} mm below the surface; wrote "
              f"{args.out / 'funnel_positions.csv'}, funnel_positions.png, funnel_presence.png")
    return 0


def cmd_spheres(args: argparse.Namespace) -> int:
    from .valentik import study

    results = study(args.csv, args.out, laws=args.law)
    print(f"{'law':16s} {'susp':>4s} {'d [mm]':>6s} {'rho_p':>6s} {'measured':>8s} {'law':>8s} {'simulated':>9s} "
          f"{'sim/law-1':>9s} {'law/meas-1':>10s}")
    for r in results:
        s = r.sphere
        print(f"{r.law:16s} {s.suspension:>4s} {s.d * 1e3:6.1f} {s.rho_p:6.0f} {s.measured:8.3f} {r.analytic:8.4f} "
              f"{r.simulated:9.4f} {r.code_error:+9.1e} {r.law_error:+10.1%}  {r.regime}")
    print(f"worst |simulated/law - 1| = {max(abs(r.code_error) for r in results):.1e}; wrote "
          f"{args.out / 'terminal_velocities.csv'}, {args.out / 'terminal_velocities.png'}")
    return 0


def positive_list(text: str) -> list[float]:
    return [positive(word) for word in text.split(",")]


def cmd_sweep(args: argparse.Namespace) -> int:
    from . import sweep

    references = dict(sweep.parse_reference(r) for r in args.reference or [])
    integrators = args.integrator.split(",") if args.integrator else None
    result = sweep.run_sweep(args.deck, args.dt, args.observe, integrators, args.parameter, references,
                             dict(args.var or []), args.np, args.out / "runs", args.tau, args.rayleigh)
    paths = sweep.write(result, args.out, args.tolerance, args.title)
    print(sweep.table(result), end="")
    print("\n".join(sweep.summary(result, args.tolerance)))
    print(f"wrote {paths[0]} and {paths[1]}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="sediment", description="SEDIMENT: settling of DEM spheres in "
                                     "fluids with LAMMPS, and sedimentation-test readouts.")
    sub = parser.add_subparsers(dest="command", required=True)

    terminal = sub.add_parser("terminal", help="terminal velocity of a sphere under a drag law")
    terminal.add_argument("--law", default="stokes", choices=_core.drag_law_names())
    terminal.add_argument("--diameter", type=positive, required=True, help="sphere diameter [m]")
    terminal.add_argument("--particle-density", type=positive, required=True, help="[kg/m3]")
    terminal.add_argument("--fluid-density", type=positive, default=998.2, help="[kg/m3] (water at 20 C)")
    terminal.add_argument("--viscosity", type=positive, default=1.002e-3,
                          help="viscosity, or plastic viscosity of a Bingham fluid [Pa s]")
    terminal.add_argument("--yield-stress", type=nonnegative, default=0.0, help="Bingham yield stress [Pa]")
    terminal.add_argument("--gravity", type=positive, default=9.81, help="[m/s2]")
    terminal.add_argument("--youngs-modulus", type=positive, help="[Pa]: also print the Rayleigh time")
    terminal.add_argument("--poisson-ratio", type=finite, default=0.3, help="for the Rayleigh time")
    terminal.set_defaults(func=cmd_terminal)

    case_a = sub.add_parser("case-a", help="single-sphere validation (case A): velocity curves and "
                            "error vs time step for the implicit and explicit integrators")
    case_a.add_argument("--out", type=Path, default=Path("out/case_a"), help="output folder")
    case_a.set_defaults(func=cmd_case_a)

    sample = sub.add_parser("sample", help="a sedimentation test as a LAMMPS scene: size classes of a PSD, "
                            "particles placed in a sub-volume of the cylinder, data file and ready deck")
    sample.add_argument("psd", type=Path, help="PSD table (CSV: diameter_um,percent_finer)")
    sample.add_argument("--out", type=Path, default=Path("out/sample"), help="output folder")
    sample.add_argument("--geometry", default="column", choices=["column", "slab"],
                        help="3D periodic column, or Bravo et al.'s 2D slab of the cylinder's axial section")
    sample.add_argument("--cylinder", default="d422", choices=["d422", "bravo"],
                        help="ASTM D422 (27.8 cm2, 0.36 m) or Bravo et al. (B 0.0635 m, H 0.457 m)")
    sample.add_argument("--height", type=positive, help="suspension height [m] (default: the cylinder's)")
    sample.add_argument("--width", type=positive, help="column side or slab width [m] (default: 2 largest "
                        "diameters; the slab spans the cylinder)")
    sample.add_argument("--mass", type=positive, default=0.060, help="dry sample mass [kg]")
    sample.add_argument("--particle-density", type=positive, default=2650.0, help="[kg/m3]")
    sample.add_argument("--classes", type=count, default=40, help="log-spaced size classes (eq. 15)")
    sample.add_argument("--particles", type=count, default=20000,
                        help="simulated particles, as parcels of equal real mass (weights)")
    sample.add_argument("--real-grains", action="store_true",
                        help="one atom per real grain at the real concentration (eq. 15 counts, at least one "
                             "per class); needed with --contacts or --lubrication")
    sample.add_argument("--law", default="dallavalle", choices=["stokes", "schiller-naumann", "dallavalle"])
    sample.add_argument("--hindered", action="store_true", help="Di Felice drag on the local concentration")
    sample.add_argument("--contacts", action="store_true", help="Hertz contacts between grains and with the floor")
    sample.add_argument("--lubrication", action="store_true", help="squeeze-film lubrication (with contacts)")
    sample.add_argument("--layers", type=count, default=400, help="layers of the concentration grid")
    sample.add_argument("--t-end", type=positive, default=86400.0, help="simulated time [s] (default 24 h)")
    sample.add_argument("--courant", type=positive, default=1.0,
                        help="layers the fastest grain in suspension may cross per step")
    sample.add_argument("--seed", type=int, default=1, help="placement seed")
    sample.set_defaults(func=cmd_sample)

    run = sub.add_parser("run", help="run a deck with lmp_sediment (serial or mpirun) with a progress bar")
    run.add_argument("deck", type=Path, help="LAMMPS input deck (e.g. from `sediment sample`)")
    run.add_argument("--np", type=count, default=1, help="MPI ranks")
    run.add_argument("--var", nargs=2, action="append", metavar=("NAME", "VALUE"), help="LAMMPS -var")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.set_defaults(func=cmd_run)

    readout = sub.add_parser("readout", help="hydrometer, buoyancy-sphere and pipette readings from a layer "
                             "file (fix layers/hdf5), with CSV tables, the granulometry figure and errors")
    readout.add_argument("layers", type=Path, nargs="?", help="layer file (HDF5)")
    readout.add_argument("--instrument", default="all", choices=["hydrometer", "buoyancy", "pipette", "all"])
    readout.add_argument("--schedule", default="d422", choices=sorted(SCHEDULE_NAMES),
                         help="reading times (the buoyancy sphere uses Bravo et al.'s unless another is given)")
    readout.add_argument("--psd", type=Path, help="input PSD (diameter_um,percent_finer) to compare with "
                         "(default: input_psd.csv beside the layer file)")
    readout.add_argument("--simulated", type=Path, help="PSD actually simulated (default: simulated_psd.csv "
                         "beside the layer file)")
    readout.add_argument("--stokes-preview", action="store_true",
                         help="without a layer file: read an analytic Stokes column of --psd")
    readout.add_argument("--height", type=positive, default=0.36, help="preview column height [m]")
    readout.add_argument("--concentration", type=positive, default=50.0, help="preview solids [g/L]")
    readout.add_argument("--particle-density", type=positive, default=2650.0, help="preview [kg/m3]")
    readout.add_argument("--surface", type=finite, help="free-surface coordinate [m] (default: top of the layers)")
    readout.add_argument("--sphere-depth", type=positive, help="buoyancy sphere centre depth [m] (default 0.3 H)")
    readout.add_argument("--pipette-depth", type=positive, default=0.10, help="[m]")
    readout.add_argument("--pipette-volume", type=positive, default=25e-6, help="[m3]")
    readout.add_argument("--hydrometer", type=positive, nargs=6,
                         metavar=("L2", "VB", "STEM_D", "MASS", "L1_R0", "L1_R50"),
                         help="a measured hydrometer instead of the nominal 152H: bulb length [m], bulb volume "
                         "[m3], stem diameter [m], mass [kg], bulb top to the R = 0 and R = 50 marks [m]")
    readout.add_argument("--viscosity", type=positive, help="viscosity for Stokes' law [Pa s] (default: the "
                         "layer file's fluid)")
    readout.add_argument("--cylinder-area", type=positive, default=27.8e-4, help="for the hydrometer's level rise [m2]")
    readout.add_argument("--out", type=Path, default=Path("out/readout"), help="output folder")
    readout.set_defaults(func=cmd_readout)

    calib = sub.add_parser("calibrate", help="paste and contact parameters from a slump, drop or tilt test")
    tests = calib.add_subparsers(dest="test", required=True)
    slump = tests.add_parser("slump", help="yield stress from a cylindrical slump test (Pashias & Boger 1996)")
    slump.add_argument("--slump", type=positive, nargs="+", required=True, help="measured slumps [m]")
    slump.add_argument("--height", type=positive, required=True, help="cylinder height [m]")
    slump.add_argument("--density", type=positive, required=True, help="paste density [kg/m3]")
    drop = tests.add_parser("restitution", help="coefficient of restitution from drop and rebound heights")
    drop.add_argument("--drop", type=positive, nargs="+", required=True, help="fall heights (any length unit)")
    drop.add_argument("--rebound", type=positive, nargs="+", required=True, help="rebound heights (same unit)")
    tilt = tests.add_parser("tilt", help="static friction from a tilt test, mu_s = H_l / L")
    tilt.add_argument("--lift", type=positive, nargs="+", required=True, help="lift heights at sliding")
    tilt.add_argument("--length", type=positive, required=True, help="plate length (same unit)")
    calib.set_defaults(func=cmd_calibrate)

    paste = sub.add_parser("paste", help="steel balls and paste backfill (cases D-F): drop test, single balls, "
                           "the funnel")
    studies = paste.add_subparsers(dest="study", required=True)
    target = studies.add_parser("restitution", help="the 'damping tsuji' input giving a restitution (drop deck)")
    target.add_argument("--target", type=positive, default=0.612)
    for name, text in (("drop-test", "rebounds of the five drops of case F with steel.lmp"),
                       ("balls", "8, 12.6 and 16 mm balls from six fall heights, with and without partial "
                                 "submergence: settling distances")):
        study = studies.add_parser(name, help=text)
        study.add_argument("--out", type=Path, default=Path("out/paste"), help="output folder")
    energy = studies.add_parser("energy", help="energy balance of one ball entering the paste")
    energy.add_argument("--diameter", type=positive, default=0.0126, help="[m]")
    energy.add_argument("--fall", type=nonnegative, default=0.255, help="fall height above the paste [m]")
    energy.add_argument("--dt", type=positive, default=1e-5, help="[s]")
    pour = studies.add_parser("funnel", help="68 balls poured from a funnel, several random packings")
    pour.add_argument("--runs", type=count, default=15)
    pour.add_argument("--jobs", type=count, default=2, help="runs at a time")
    pour.add_argument("--dt", type=positive, default=1e-6, help="[s]")
    pour.add_argument("--out", type=Path, default=Path("out/paste"), help="output folder")
    paste.set_defaults(func=cmd_paste)

    spheres = sub.add_parser("spheres", help="terminal velocities of spheres in Bingham suspensions, simulated vs "
                             "the law and the measurement (Valentik & Whitmore 1965 columns)")
    spheres.add_argument("csv", type=Path, help="CSV with suspension,rho_f,eta_B,tau_y,d,rho_p,v_ter_measured (SI)")
    spheres.add_argument("--law", nargs="+", default=["zhang-li", "zhang-li/smooth"],
                         choices=["zhang-li", "zhang-li/smooth"])
    spheres.add_argument("--out", type=Path, default=Path("out/spheres"), help="output folder")
    spheres.set_defaults(func=cmd_spheres)

    sweep = sub.add_parser("sweep", help="accuracy vs cost: a deck at several time steps (and integrators), "
                           "errors against a reference, loop times, table and figure",
                           description="Runs DECK with -var dt VALUE for each value (and -var integrator "
                           "nve/sphere/fluid|nve/sphere), reads the observables it prints (RESULT name value; "
                           "SERIES name x y) or the readout curves of the layer file it writes, and scores "
                           "each run against --reference or the finest run. See docs/sweep.md.")
    sweep.add_argument("deck", type=Path, help="LAMMPS deck with 'variable dt index ...'")
    sweep.add_argument("--dt", type=positive_list, required=True, help="comma-separated values of the swept variable")
    sweep.add_argument("--parameter", default="dt", help="the deck variable swept (default dt; e.g. courant for a "
                       "deck written by `sediment sample`)")
    sweep.add_argument("--integrator", help="comma-separated: implicit (nve/sphere/fluid), explicit (nve/sphere)")
    sweep.add_argument("--observe", nargs="+", required=True, metavar="NAME",
                       help="RESULT or SERIES names the deck prints, or hydrometer, buoyancy, pipette")
    sweep.add_argument("--reference", action="append", metavar="NAME=EXPR",
                       help="analytic reference: a number, or an expression of x for a series "
                       "(numpy exp, log, sqrt, ...); default: the finest run")
    sweep.add_argument("--tolerance", type=positive, default=0.01, help="relative error to meet (default 1 %%)")
    sweep.add_argument("--tau", type=positive, help="drag relaxation time [s]: marks the explicit limit 2 tau")
    sweep.add_argument("--rayleigh", type=positive, help="Rayleigh time [s]: marks the 20 %% rule")
    sweep.add_argument("--var", nargs=2, action="append", metavar=("NAME", "VALUE"), help="LAMMPS -var for every run")
    sweep.add_argument("--np", type=count, default=1, help="MPI ranks per run")
    sweep.add_argument("--title", default="", help="figure title")
    sweep.add_argument("--out", type=Path, default=Path("out/sweep"), help="output folder")
    sweep.set_defaults(func=cmd_sweep)
    return parser


def main(argv: list[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    try:
        return args.func(args)
    except (ValueError, FileNotFoundError, RuntimeError) as exc:
        print(f"sediment {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
