# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment sample: a sedimentation test as a LAMMPS scene."""
from __future__ import annotations

import argparse
from pathlib import Path

from ..constants import DRAGS, HINDRANCES, LAB_TEMPERATURE, SOIL_PARTICLE_DENSITY, SPECIMEN_MASS
from .types import count, positive, quantity, temperature


EXAMPLES = [
    'sediment sample examples/granulometry/psd/sample5.csv --out out/sample5',
    'sediment sample examples/granulometry/psd/sample5.csv --plan out/plan/report.json --out out/sample5',
]


def add_parser(commands) -> argparse.ArgumentParser:
    """Adds the command and its options."""
    parser = commands.add_parser("sample", help="a sedimentation test as a LAMMPS scene: size classes of a PSD, "
                                 "particles placed in a sub-volume of the cylinder, data file and ready deck")
    parser.add_argument("psd", type=Path, help="PSD table (CSV: diameter_um,percent_finer)")
    parser.add_argument("--out", type=Path, default=Path("out/sample"), help="output folder")
    add_test_options(parser)
    parser.add_argument("--particles", type=count, default=20000,
                        help="simulated particles, as parcels of equal real mass (weights)")
    parser.add_argument("--real-grains", action="store_true",
                        help="one atom per real grain at the real concentration (eq. 15 counts, at least one "
                             "per class); needed with --contacts or --lubrication")
    parser.add_argument("--drag", default="standard", choices=DRAGS,
                        help="single-sphere drag: the measured standard drag curve (default), another law, or "
                        "difelice, Bravo et al.'s model (Dallavalle's curve with Di Felice's hindrance)")
    parser.add_argument("--hindrance", choices=HINDRANCES,
                        help="how the local concentration slows the grains: richardson-zaki (default; Rowe's fit "
                        "of Richardson & Zaki's measured exponent, 4.7 at low Re), garside (Garside & Al-Dibouni, "
                        "5.1), difelice, none (drag difelice carries its own)")
    parser.add_argument("--contacts", action="store_true", help="Hertz contacts between grains and with the floor")
    parser.add_argument("--lubrication", action="store_true", help="squeeze-film lubrication (with contacts)")
    parser.add_argument("--two-way", action="store_true",
                        help="two-way coupling: the flow the grains drive (fix fluid/flow), in a column three swirls "
                        "wide with parcels placed independently; the deck's `-var flow no` runs its one-way twin")
    parser.add_argument("--flow-cells", type=count, metavar="N",
                        help="with --two-way: fix fluid/flow's cubic cells across the column (default 16; a size "
                        "the FFTs take; docs/effects.md section 3 shows what the grid changes)")
    parser.add_argument("--courant", type=positive, default=4.0,
                        help="layers the fastest grain in suspension may cross per step (default 4: within 0.25 "
                        "points of percent finer of Courant 1 for the five samples of docs/effects.md)")
    parser.add_argument("--force", action="store_true",
                        help="delete the files of a run in --out whose deck or data this sample changes (its layer "
                        "file, restart files, logs) instead of refusing")
    parser.add_argument("--plan", type=Path, metavar="REPORT",
                        help="take the drag, hindrance, parcels and Courant number that `sediment plan` decided "
                        "(its report.json) instead of --drag, --hindrance, --particles and --courant (and whether "
                        "to couple two ways, on which grid)")
    return parser


def add_test_options(parser: argparse.ArgumentParser) -> None:
    """The options that describe the test itself (shared with `sediment plan`)."""
    parser.add_argument("--geometry", default="column", choices=["column", "slab"],
                        help="3D periodic column, or Bravo et al.'s 2D slab of the cylinder's axial section")
    parser.add_argument("--cylinder", default="d422", choices=["d422", "bravo"],
                        help="ASTM D422 (27.8 cm2, 0.36 m) or Bravo et al. (B 0.0635 m, H 0.457 m)")
    parser.add_argument("--height", type=quantity("suspension_height"),
                        help="suspension height [m] (default: the cylinder's)")
    parser.add_argument("--width", type=quantity("column_width"),
                        help="column side or slab width [m] (default: 2 largest "
                        "diameters; the slab spans the cylinder)")
    parser.add_argument("--mass", type=quantity("specimen_mass"), default=SPECIMEN_MASS, help="dry sample mass [kg]")
    parser.add_argument("--particle-density", type=quantity("particle_density"),
                        default=SOIL_PARTICLE_DENSITY, help="[kg/m3]")
    parser.add_argument("--temperature", type=temperature, default=LAB_TEMPERATURE,
                        help="water temperature [C], 0-40: its density and viscosity (default 20; 1 C moves the "
                        "viscosity by about 2.5 %%)")
    parser.add_argument("--temperature-record", type=Path, metavar="CSV",
                        help="the water's temperature over the test (columns time_min,temperature_C; a hydrometer "
                        "sheet serves): the run's water follows it, linear between rows, instead of --temperature")
    parser.add_argument("--classes", type=count, default=40, help="log-spaced size classes (eq. 15)")
    parser.add_argument("--layers", type=count, default=400, help="layers of the concentration grid")
    parser.add_argument("--t-end", type=quantity("t_end"), default=86400.0, help="simulated time [s] (default 24 h)")
    parser.add_argument("--seed", type=int, default=1, help="placement seed")


def suspension_of(args: argparse.Namespace):
    """The water at the test's temperature and the grains."""
    from ..lab.readout import Suspension

    return Suspension.at_temperature(args.temperature, args.particle_density)


def effects_of(args: argparse.Namespace, contacts: bool = False, lubrication: bool = False):
    """The drag law and hindrance the options name (drag difelice carries its own hindrance)."""
    from ..sim.scene import Effects

    if args.drag == "difelice" and args.hindrance not in (None, "difelice"):
        raise ValueError("--drag difelice is Dallavalle's curve with Di Felice's hindrance (Bravo et al.): it takes no "
                         f"--hindrance {args.hindrance}; for that hindrance choose --drag dallavalle or standard")
    hindrance = args.hindrance or ("difelice" if args.drag == "difelice" else "richardson-zaki")
    return Effects(args.drag, contacts, lubrication, hindrance, flow=args.two_way)


def cylinder_of(args: argparse.Namespace):
    """The cylinder the test options name."""
    from ..sim.scene import Cylinder

    cylinder = Cylinder.bravo() if args.cylinder == "bravo" else Cylinder()
    return cylinder if args.height is None else Cylinder(cylinder.area, args.height)


def run(args: argparse.Namespace) -> int:
    """Plans the scene, prints it and writes its data file, deck and PSD tables."""
    from ..lab.psd import read_psd
    from ..sim.scene import FLOW_CELLS_ACROSS, plan
    from ..sim.scenefiles import describe, runs_replaced, write

    psd = read_psd(args.psd)
    record = ()
    if args.temperature_record is not None:
        from ..lab.sheet import read_temperature_record

        record = read_temperature_record(args.temperature_record, args.t_end)
    if args.plan is not None:
        from ..planner.scenes import decided_options

        if args.real_grains:
            raise ValueError("--plan decides a number of parcels: it does not go with --real-grains")
        decided, planned = decided_options(args.plan)
        if not decided["two_way"]:
            decided["flow_cells"] = None
        # the plan decides whether to couple two ways and on which grid: a different wish is refused
        asked = [f"--{name.replace('_', '-')}" for name, given in (("two_way", args.two_way),
                                                                  ("flow_cells", args.flow_cells))
                 if given not in (None, False) and given != decided[name]]
        if asked:
            coupling = (f"two-way coupling on {decided['flow_cells']} cells across" if decided["two_way"]
                        else "one-way coupling")
            raise ValueError(f"{args.plan} decided {coupling}: {' and '.join(asked)} would change that; sample "
                             "without --plan to choose it")
        for name, value in decided.items():
            setattr(args, name, value)
        cylinder = cylinder_of(args)
        here = dict(geometry=args.geometry, width=args.width, classes=args.classes, layers=args.layers,
                    t_end=args.t_end, mass=args.mass, particle_density=args.particle_density,
                    cylinder_area=cylinder.area, height=cylinder.height, temperature=args.temperature)
        differ = [f"{k} {planned[k]} (here {v})" for k, v in here.items() if k in planned and planned[k] != v]
        # a plan of an earlier version recorded no temperature record: it planned for a constant water
        if [list(r) for r in record] != planned.get("temperature_record", []):
            differ.append(f"the temperature record ({_record_name(planned.get('temperature_record', []))} in the "
                          f"plan, here {args.temperature_record or 'none'}: {_record_name(record)})")
        if "psd" not in planned:
            print(f"warning: {args.plan} does not record the PSD it was made for (a plan of an earlier version)")
        elif not _same_psd(planned["psd"], psd):
            differ.insert(0, f"the PSD ({args.psd} differs from the plan's)")
        if differ:
            raise ValueError(f"{args.plan} was made for another test: " + ", ".join(differ) +
                             "; plan this one (sediment plan) or sample without --plan")
        print(f"the plan's decision ({args.plan}): --drag {args.drag} --hindrance {args.hindrance} "
              f"--particles {args.particles} --courant {args.courant:g}"
              + (f" --two-way --flow-cells {args.flow_cells}" if args.two_way else ""))

    if args.flow_cells is not None and not args.two_way:
        raise ValueError("--flow-cells sets the grid of --two-way's flow: give both")
    suspension = suspension_of(args)
    if record:
        from ..lab.readout import Suspension

        # the time steps for the warmest water of the record, where the grains fall fastest
        suspension = Suspension.at_temperature(max(t for _, t in record), args.particle_density)
    scene = plan(psd, geometry=args.geometry, cylinder=cylinder_of(args), mass=args.mass,
                 suspension=suspension, width=args.width,
                 classes=args.classes, particles=None if args.real_grains else args.particles,
                 effects=effects_of(args, args.contacts, args.lubrication),
                 layers=args.layers, t_end=args.t_end, courant=args.courant, seed=args.seed,
                 flow_cells=args.flow_cells or FLOW_CELLS_ACROSS)
    scene.water_record = record
    print(describe(scene))
    write(scene, args.out)
    args.outputs.remove_also(runs_replaced(args.final_out, args.out / "in.sedimentation", force=args.force))
    print(f"next: sediment run {args.final_out / 'in.sedimentation'}")
    return 0


def _record_name(record) -> str:
    """A temperature record in a few words."""
    if not record:
        return "none"
    temperatures = [t for _, t in record]
    return f"{len(record)} rows over {record[-1][0] / 60:g} min, {min(temperatures):g}-{max(temperatures):g} C"


def _same_psd(recorded: dict, psd) -> bool:
    """Whether a plan's recorded PSD is this one (to the digits a report keeps)."""
    import numpy as np

    try:
        d, p = np.asarray(recorded["diameter_um"], float), np.asarray(recorded["percent_finer"], float)
    except (KeyError, TypeError, ValueError):
        return False
    return (d.shape == psd.diameter.shape and np.allclose(d, psd.diameter * 1e6, rtol=1e-9, atol=0)
            and np.allclose(p, psd.percent_finer, rtol=1e-9, atol=1e-9))
