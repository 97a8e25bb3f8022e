# SPDX-License-Identifier: GPL-2.0-or-later
"""Deck tests of what the styles refuse: numerical guards and lost atoms, malformed input each stopped
with its error message, and generated malformed commands (fuzz.py). Registered with the others of
checks.py (harness.check), run as `python3 checks.py NAME [--np N]`."""
from __future__ import annotations

import tempfile
from pathlib import Path

from harness import G, check, died, report, run_batch, run_deck


# ---- numerical guards and lost atoms ---------------------------------------------------------
GUARD_SCENE = """units si
atom_style sphere
atom_modify map array
boundary p p f
region box block -0.01 0.01 -0.01 0.01 -0.05 0.05
create_box 1 box
create_atoms 1 single 0 0 0.01
create_atoms 1 single 0.005 0 -0.01
set atom * diameter 1e-3 density 2500
comm_modify cutoff 0.001
fix grav all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3 surface z 0
fix buoy all fluid/buoyancy water
"""


def guard_deck(tmp: Path, name: str, body: str) -> Path:
    deck = tmp / f"{name}.lmp"
    deck.write_text(GUARD_SCENE + body + "\n")
    return deck


@check
def guards(np_ranks: int):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        # A sphere in the air above the free surface: counted, and it falls exactly as under nve/sphere.
        out = run_deck(guard_deck(tmp, "outside", """fix drag all fluid/drag water law stokes
fix step all nve/sphere/fluid
timestep 1e-4
run 10
print "RESULT outside $(f_step[3]) stuck $(f_step[1]) capped $(f_step[4]) vz1 $(vz[1]:%.17g) vz2 $(vz[2]:%.17g)"
"""), {}, np_ranks, cwd=tmp)
        r = out.results
        report(f"guards: outside-the-fluid count {r['outside']:.0f}; the sphere in the air falls at {r['vz1']:.17g} m/s "
               f"(g t = {-G * 1e-3:.17g}), the immersed one at {r['vz2']:.6g}")
        assert r["outside"] == 1 and r["stuck"] == 0 and r["capped"] == 0
        assert abs(r["vz1"] + G * 1e-3) < 1e-15 and -G * 1e-3 < r["vz2"] < 0
        # The same spheres integrated explicitly: fluid/drag counts its own.
        out = run_deck(guard_deck(tmp, "explicit", """set atom 2 diameter 1e-4 density 2500
fix drag all fluid/drag water law stokes
fix step all nve/sphere
timestep 1e-2
run 1
print "RESULT unstable $(f_drag[4]) outside $(f_drag[5])"
"""), {}, np_ranks, cwd=tmp)
        report(f"guards: explicit drag at dt = 0.01 s (tau of the immersed sphere 1.4 ms): {out.results['unstable']:.0f} sphere(s) with dt > 2 tau, "
               f"{out.results['outside']:.0f} outside the fluid")
        assert out.results == {"unstable": 1.0, "outside": 1.0}
        assert "have dt > 2 tau under explicit drag" in out.text
        # Local solid fraction above max_fraction: counted, drag evaluated at the cap.
        out = run_deck(guard_deck(tmp, "capped", """compute conc all concentration/grid layers z 10 bounds -0.05 0.05
fix drag all fluid/drag water law difelice concentration c_conc max_fraction 1e-6
fix step all nve/sphere/fluid
timestep 1e-4
run 2
print "RESULT capped $(f_step[4]) outside $(f_step[3])"
"""), {}, np_ranks, cwd=tmp)
        report(f"guards: local fraction above max_fraction 1e-6: {out.results['capped']:.0f} sphere(s)")
        assert out.results == {"capped": 1.0, "outside": 1.0}
        # A force that overflows: stopped at once, naming the atom, instead of NaN spreading; on every
        # path of the step: no fluid/drag at all, a sphere in the air (atom 1) and one in the water
        # (atom 2) under the linear and the blocked smooth step.
        for name, drag, pushed in (("bare", "", 1), ("stokes", "fix drag all fluid/drag water law stokes", 1),
                                   ("stokes_immersed", "fix drag all fluid/drag water law stokes", 2),
                                   ("dallavalle", "fix drag all fluid/drag water law dallavalle", 2)):
            out = run_deck(guard_deck(tmp, f"overflow_{name}", f"""{drag}
fix step all nve/sphere/fluid
group pushed id {pushed}
fix push pushed addforce 0 0 1e308
timestep 1e-4
run 10
"""), {}, np_ranks, expect_failure=True, cwd=tmp)
            assert f"Fix nve/sphere/fluid: atom {pushed} has a non-finite position or velocity at step 1" in out.text, \
                f"overflow on the {name} path not caught:\n{out.text[-2000:]}"
        # A NaN force pressing a grain that rests on the floor (atom 2 sits on it from the start): not
        # taken for a grain at rest, nor put back on the floor, but stopped at once.
        for law in ("stokes", "dallavalle"):
            out = run_deck(guard_deck(tmp, f"nan_at_rest_{law}", f"""fix drag all fluid/drag water law {law}
fix step all nve/sphere/fluid floor z -0.0105
timestep 1e-3
run 20
print "RESULT z2 $(z[2]:%.17g) vz2 $(vz[2])"
variable nan equal (1e308*10)-(1e308*10)
group resting id 2
fix push resting addforce 0 0 v_nan
run 20
"""), {}, np_ranks, expect_failure=True, cwd=tmp)
            assert out.results == {"z2": -0.01, "vz2": 0.0}, out.results
            assert "Fix nve/sphere/fluid: atom 2 has a non-finite position or velocity at step 21" in out.text, \
                f"a NaN force on a grain at rest under {law} not caught:\n{out.text[-2000:]}"
        # Spheres leaving the box: LAMMPS's lost-atom policy applies, the fixes carry on with the rest.
        leave = """fix drag all fluid/drag water law stokes
fix step all nve/sphere/fluid
velocity all set 0 0 0
set atom 1 vz 30
timestep 1e-4
thermo_style custom step atoms f_step[3]
thermo 10
{policy}
run 100
print "RESULT atoms $(atoms) outside $(f_step[3])"
"""
        out = run_deck(guard_deck(tmp, "lost_ignore", leave.format(policy="thermo_modify lost ignore")), {}, np_ranks,
                       cwd=tmp)
        report(f"guards: a sphere shot out of the box with 'lost ignore': {out.results['atoms']:.0f} atom left, "
               f"{out.results['outside']:.0f} outside the fluid")
        assert out.results == {"atoms": 1.0, "outside": 0.0}
        out = run_deck(guard_deck(tmp, "lost_error", leave.format(policy="")), {}, np_ranks, expect_failure=True,
                       cwd=tmp)
        assert "ERROR: Lost atoms: original 2 current 1" in out.text


# ---- bad input ----------------------------------------------------------------------------------
# Current LAMMPS refuses numbers beyond the double range in utils::numeric itself, before the style
# sees them; LAMMPS 2021 turns them into inf, which the style refuses.
OUT_OF_RANGE = "is out of range"
ONE_SPHERE = "create_atoms 1 single 0.5 0.5 0.5\nset atom 1 diameter 1e-3 density 2500\n"
FLOW = "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\n"
STRATIFIED_FLOW = ("fix w all property/atom d_w\nfix u all fluid/flow f grid 8 8 8 column 0 1 weight d_w "
                   "stratification grains\nrun 0")
BAD_INPUT = [
    ("fix f all fluid density -1 viscosity 1e-3", "density must be finite and > 0"),
    ("fix f all fluid density 1e400 viscosity 1e-3", ("density must be finite and > 0", OUT_OF_RANGE)),
    ("fix f all fluid density 1000 viscosity 0", "viscosity must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e999", ("viscosity must be finite and > 0", OUT_OF_RANGE)),
    ("fix f all fluid density 1000 viscosity nan", "Expected floating point parameter"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface plane 0 0 0 0 0 0", "normal must be finite and non-zero"),
    ("fix f all fluid density 1000", "give exactly one of 'viscosity MU' or 'bingham TAU_Y ETA_B'"),
    ("fix f all fluid viscosity 1e-3", "keyword 'density' is required"),
    ("fix f all fluid density 1000 viscosity 1e-3 colour red", "unknown keyword 'colour'"),
    ("fix f all fluid density 1000 bingham -3 0.1", "bingham yield stress must be finite and > 0"),
    ("fix f all fluid density 1000 bingham 3 -0.1", "bingham plastic viscosity must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface w 0", "surface axis must be x, y, z or plane"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface z v_nolevel\nrun 0", "surface variable 'nolevel' does not exist"),
    ("variable h atom z\nfix f all fluid density 1000 viscosity 1e-3 surface z v_h\nrun 0", "surface variable 'h' must be equal-style"),
    ("fix f all fluid density 1000 viscosity 1e-3 surface z 0 crossing middle", "crossing must be cap or centre, not 'middle'"),
    ("fix f all fluid density 1000 viscosity 1e-3 crossing centre", "keyword 'crossing' needs a 'surface'"),
    ("fix f all fluid density 1000 viscosity", "keyword 'viscosity' needs 1 value"),
    ("fix f all fluid density abc viscosity 1e-3", "Expected floating point parameter"),
    ("fix f all fluid density 1000 viscosity 1e-3 region nowhere\nrun 0", "region 'nowhere' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stoke", "unknown law 'stoke'"),
    ("fix d all fluid/drag nofluid law stokes\nrun 0", "fluid fix 'nofluid' does not exist"),
    ("fix d all fluid/drag grav law stokes\nrun 0", "fix 'grav' is a fix gravity, not a fix fluid"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f", "expected 'fix ID group fluid/drag FLUID-ID law NAME'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f rotation yes", "keyword 'law' is required"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes rotation maybe", "rotation must be yes or no"),
    ("unfix grav\nfix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f\nrun 0", "needs a fix gravity"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f gravity f\nrun 0", "is a fix fluid, not a fix gravity"),
    ("fix n all nve/sphere/fluid extra", "unknown keyword 'extra' (expected floor or surface)"),
    ("fix n all nve/sphere/fluid floor z", "'floor' needs an axis and a coordinate"),
    ("fix n all nve/sphere/fluid floor x 0 floor z 0", "one floor per fix"),
    ("fix n all nve/sphere/fluid floor w 0", "floor axis must be x, y or z, not 'w'"),
    ("fix n all nve/sphere/fluid surface z 1 surface z 2", "one surface per fix"),
    ("fix n all nve/sphere/fluid surface q 1", "surface axis must be x, y or z, not 'q'"),
    ("fix n all nve/sphere/fluid floor z 0 surface x 1", "the floor and the surface lie across one axis, not z and x"),
    ("fix n all nve/sphere/fluid surface z 0.5 floor z 0.5", "the surface 0.5 must lie above the floor 0.5"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c", "'mixture' needs c_ID and the solid density"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c -5", "mixture solid density must be finite and > 0"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f mixture c_c 2650\nrun 0", "compute 'c' does not exist"),
    ("pair_style lubricate/fluid", "needs the ID of a fix fluid"),
    ("pair_style lubricate/fluid w inner 0.5 outer 0.1", "need 0 < inner < outer"),
    ("pair_style lubricate/fluid w squeeze 2", "unknown keyword 'squeeze'"),
    ("pair_style lubricate/fluid w limit maybe", "limit must be yes or no, not 'maybe'"),
    ("pair_style lubricate/fluid w repulsion -1", "repulsion force scale must be finite and > 0"),
    ("pair_style lubricate/fluid w\npair_coeff * * 1.0", "pair_coeff takes the two types only"),
    ("fix w all fluid density 1000 viscosity 1e-3\npair_style lubricate/fluid w\npair_coeff * *\nrun 0",
     "use 'comm_modify vel yes'"),
    ("comm_modify vel yes\npair_style lubricate/fluid nowater\npair_coeff * *\nrun 0", "Pair lubricate/fluid: fluid fix 'nowater' does not exist"),
    ("compute o all contact/overlap every", "unknown keyword 'every'"),
    ("compute o all contact/overlap\nthermo_style custom c_o\nrun 0", "needs a pair style"),
    ("compute c all concentration/grid", "the grid is required: 'layers AXIS N' or 'cells NX NY NZ'"),
    ("compute c all concentration/grid cells 4 4", "'cells' needs 3 counts in a 3d simulation"),
    ("compute c all concentration/grid cells 4 4 4 bounds 0 1 0 1", "'bounds' needs 6 values (xlo xhi ylo yhi zlo zhi)"),
    ("compute c all concentration/grid cells 4 4 4 layers z 3", "give either 'layers' or 'cells', once"),
    ("compute c all concentration/grid cells 4 4 4\nfix l all layers/hdf5 10 a.h5 c_c\nrun 0", "bins into 3d cells"),
    ("compute c all concentration/grid layers w 10", "layer axis must be x, y or z"),
    ("compute c all concentration/grid layers z 0", "layers count 0 must be from 1 to 200000000"),
    ("compute c all concentration/grid layers z 2000000000", "layers count 2000000000 must be from 1 to 200000000"),
    ("compute c all concentration/grid layers z 3000000000", "layers count 3000000000 must be from 1 to 200000000"),
    ("compute c all concentration/grid cells 1000 1000 1000", "columns is more than 2e+08 values"),
    ("compute c all concentration/grid layers z 10 bounds 1 0", "bounds need LO < HI along z"),
    ("compute c all concentration/grid layers z 10 classes 2 1", "positive and increasing"),
    ("compute c all concentration/grid layers z 10 thickness 1", "'thickness' is for 2d simulations only"),
    ("compute c all concentration/grid layers z 10 smooth -1", "smooth width must be finite and > 0"),
    ("compute c all concentration/grid layers z 10 sieve 3", "unknown keyword 'sieve'"),
    ("compute c all concentration/grid layers z 10 every 0", "every count 0 must be from 1 to"),
    ("compute c all concentration/grid layers z 10 every 2.5", "Expected integer"),
    ("compute c all concentration/grid layers z 10 weight w", "'weight' needs a per-atom property d_NAME"),
    ("compute c all concentration/grid layers z 10 weight d_w\nrun 0", "weight d_w is not a per-atom floating-point vector"),
    ("fix l all layers/hdf5 0 a.h5 c_c", "N must be > 0"),
    ("fix l all layers/hdf5 10 a.h5 conc", "expected a compute reference c_ID"),
    ("fix l all layers/hdf5 10 a.h5 c_nothing\nrun 0", "compute 'nothing' does not exist"),
    ("compute t all temp\nfix l all layers/hdf5 10 a.h5 c_t\nrun 0", "not a compute concentration/grid"),
    ("fix l all layers/hdf5 10 a.h5 c_c colour 1", "unknown keyword 'colour'"),
    ("compute c all concentration/grid layers z 10\nshell echo not hdf5 > notes.h5\nfix l all layers/hdf5 10 notes.h5 c_c\nrun 0", "exists but is not an HDF5 file; not overwriting it"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice", "law difelice needs keyword 'concentration c_ID'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes concentration c_x", "keyword 'concentration' goes with a hindrance"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standard hindrance richardson-zaki", "hindrance richardson-zaki needs keyword 'concentration c_ID'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standard hindrance rz concentration c_x", "unknown hindrance 'rz'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law zhang-li hindrance difelice concentration c_x", "law zhang-li takes no hindrance difelice"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law schiller-naumann hindrance garside concentration c_x", "jump in Cd at Re = 1000"),
    ("fix f all fluid density 1000 bingham 10 0.01\nfix d all fluid/drag f law bingham hindrance richardson-zaki concentration c_x", "law bingham takes no hindrance richardson-zaki"),
    ("fix f all fluid density 1000 bingham 10 0.01\nfix d all fluid/drag f law Bingham", "unknown law 'Bingham'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice hindrance garside concentration c_x", "law difelice is law dallavalle's drag with hindrance difelice"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law standart", "unknown law 'standart'"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix b all fluid/buoyancy f max_fraction 1", "max_fraction must be in (0, 1)"),
    # what the styles cannot honour
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix b1 all fluid/buoyancy f\nfix b2 all fluid/buoyancy f\nrun 0",
     "fixes b1 and b2 both give the buoyancy of fluid f to 1 atom(s)"),
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep 0\n"
     "fix s all nve/sphere/fluid\nrun 1", "the timestep must be > 0, not 0"),
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep -0.001\n"
     "fix s all nve/sphere/fluid\nrun 1", "the timestep must be > 0, not -0.001"),
    ("compute c all concentration/grid layers z 10 bounds 2 3\nrun 0", "lie wholly outside the box"),
    # a floor above the grains would lift every one onto it at the first step (and grow a shrink-wrapped box)
    (ONE_SPHERE + "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\ntimestep 1e-4\n"
     "fix s all nve/sphere/fluid floor z 0.9\nrun 1", "floor z 0.9 lies above every sphere (atom 1, the lowest, at z 0.5"),
    ("fix f all fluid density 1000 viscosity 1e-3\ncompute c all concentration/grid layers z 10\n"
     "fix l all layers/hdf5 1 '' c_c", "'' names no file"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x\nrun 0", "compute 'x' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x buoyancy heavy", "buoyancy must be plain or mixture"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law difelice concentration c_x max_fraction 1.2", "max_fraction must be in (0, 1)"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 swirl 1", "Fix fluid/flow: unknown keyword 'swirl'"),
    (FLOW + "fix u all fluid/flow f grid 8 14 8", "Fix fluid/flow: grid size 14 in y is not a product of 2, 3 and 5"),
    (FLOW + "fix u all fluid/flow f grid 8 8", "expected 'fix ID group fluid/flow FLUID-ID grid NX NY NZ"),
    (FLOW + "fix u all fluid/flow f grid 8 8 16\nrun 0", "Fix fluid/flow: the grid's cells must be cubes"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 brinkman -1", "Fix fluid/flow: brinkman resistance must be >= 0"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 every 0", "Fix fluid/flow: every count 0 must be from 1 to 1000000"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 drift -0.1", "Fix fluid/flow: drift must be finite and > 0"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 drift 1", "Fix fluid/flow: drift 1 must be below 1"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 drift 0.1 every 4", "Fix fluid/flow: give 'every N' or 'drift D', not both"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 every 1 drift 0.1", "Fix fluid/flow: give 'every N' or 'drift D', not both"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 cfl 0", "Fix fluid/flow: cfl must be finite and > 0"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 cfl 1.5", "Fix fluid/flow: cfl 1.5 must be at most 1"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 cfl", "Fix fluid/flow: keyword 'cfl' needs a distance in cells"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 cfl 0.5\nfix r all dt/reset 1 NULL NULL 1e-6\nrun 0",
     "Fix fluid/flow: keyword cfl sets the time step, as fix r dt/reset does: give one of them"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 column 0 1e-3", "Fix fluid/flow: keyword 'column' closes the fluid at its"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 weight 8", "Fix fluid/flow: 'weight' needs a per-atom property d_NAME"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 weight d_w\nrun 0",
     "Fix fluid/flow: weight d_w is not a per-atom floating-point vector"),
    (ONE_SPHERE + FLOW + "fix w all property/atom d_w\nfix u all fluid/flow f grid 8 8 8 weight d_w\nrun 0",
     "Fix fluid/flow: 1 atoms have a weight d_w that is not > 0"),
    (FLOW + "fix u all fluid/flow f grid 2 2 2", "Fix fluid/flow: grid size 2 in x is smaller than the kernel's 4 nodes"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 stratification real", "Fix fluid/flow: stratification must be parcels or grains"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 stratification", "Fix fluid/flow: keyword 'stratification' needs grains or parcels"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 across wide", "Fix fluid/flow: across must be vessel or periodic"),
    (FLOW + "fix u all fluid/flow f grid 8 8 8 across", "Fix fluid/flow: keyword 'across' needs vessel or periodic"),
    (FLOW + "fix w all property/atom d_w\nfix u all fluid/flow f grid 8 8 8 weight d_w stratification grains",
     "Fix fluid/flow: 'stratification grains' is for parcels (keyword weight) in a closed column"),
    ("unfix grav\nchange_box all boundary p p f\n" + FLOW + STRATIFIED_FLOW,
     "Fix fluid/flow with 'stratification grains' needs a fix gravity"),
    ("fix tilt all gravity 1 vector 1 0 0\nchange_box all boundary p p f\n" + FLOW + STRATIFIED_FLOW,
     "Fix fluid/flow with 'stratification grains': several fix gravity are defined"),
    ("fix f all fluid density 1000 viscosity -1e-3\nfix u all fluid/flow f grid 8 8 8", "Fix fluid: viscosity must be finite and > 0"),
    ("fix u all fluid/flow water grid 8 8 8\nrun 0", "Fix fluid/flow: fluid fix 'water' does not exist"),
    ("fix f all fluid density 1000 viscosity 1e-3\nfix u all fluid/flow f grid 8 8 8\nrun 0",
     "Fix fluid/flow: no fix fluid/drag takes its drag from fluid 'f'"),
    ("fix f all fluid density 1000 bingham 1 0.1\nfix d all fluid/drag f law bingham\nfix u all fluid/flow f grid 8 8 8\nrun 0",
     "Fix fluid/flow: fluid 'f' is a Bingham fluid"),
]


@check
def bad_input(np_ranks: int):
    from concurrent.futures import ThreadPoolExecutor

    def verdict(k: int) -> str | None:
        lines, messages = BAD_INPUT[k]
        folder = Path(tmp) / f"bad{k}"
        folder.mkdir()
        deck = folder / "deck.lmp"
        deck.write_text("units si\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                        "fix grav all gravity 9.81 vector 0 0 -1\n" + lines + "\n")
        out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=folder)
        messages = (messages,) if isinstance(messages, str) else messages
        if "ERROR" not in out.text or not any(m in out.text for m in messages):
            return f"{lines!r}: expected {' or '.join(messages)}; got {out.error}"
        if out.returncode < 0:    # refused, then died of a signal on the way out
            return f"{lines!r}: {died(out)}"
        return None

    with tempfile.TemporaryDirectory() as tmp:
        # Four decks at a time: a failing deck's run is mostly MPI's start-up and shutdown, waiting
        # (74 decks on 2 ranks: 127 s one at a time, 64 s two, 35 s four; user + system time 13 s).
        with ThreadPoolExecutor(max_workers=4) as pool:
            wrong = [w for w in pool.map(verdict, range(len(BAD_INPUT))) if w]
        assert not wrong, "\n".join(wrong)
        for units in ("metal", "real"):
            deck = Path(tmp) / "units.lmp"
            deck.write_text(f"units {units}\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                            "fix f all fluid density 1 viscosity 1\nrun 0\n")
            out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=Path(tmp))
            assert f"requires coherent units (si, cgs, micro, nano or lj), not '{units}'" in out.text
        deck = Path(tmp) / "atomic.lmp"
        deck.write_text("units si\natom_style atomic\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                        "fix f all fluid density 1000 viscosity 1e-3\nfix d all fluid/drag f law stokes\n")
        out = run_deck(deck, {}, np_ranks, expect_failure=True, cwd=Path(tmp))
        assert "requires atom attributes radius and rmass" in out.text
    report(f"bad input: {len(BAD_INPUT) + 3} malformed decks each stopped with the expected error message")


@check(ranks=(1,))
def fuzz_input(np_ranks: int):
    """Every malformed command of tests/decks/fuzz.py ends with a LAMMPS error; valid ones run."""
    import subprocess
    from concurrent.futures import ThreadPoolExecutor

    import fuzz

    def outcome(case_and_dir):
        case, folder = case_and_dir
        deck = folder / "deck.lmp"
        deck.write_text(case.deck)
        # A hang is a run that never ends: 300 s, not 60, so that a deck which ends in under a second
        # alone is not called one on a loaded machine (a fresh clone's, load average above 11).
        try:
            out = run_batch(deck, {}, np_ranks, cwd=folder, timeout=300, check=False)
        except subprocess.TimeoutExpired:
            return case, "hang"
        refused = out.returncode != 0 and out.error is not None and out.error.startswith("ERROR")
        ran = out.returncode == 0 and out.error is None and "Loop time" in out.text
        if refused:
            return case, "refused" if not case.valid else "valid input refused: " + out.error
        if ran:
            return case, "ran" if case.valid else "silently accepted"
        return case, died(out)

    cases = fuzz.cases()
    with tempfile.TemporaryDirectory() as tmp:
        folders = [Path(tmp) / f"case{k}" for k in range(len(cases))]
        for folder in folders:
            folder.mkdir()
        # Four at a time: like bad_input's, these runs mostly wait on start-up and shutdown.
        with ThreadPoolExecutor(max_workers=4) as pool:
            results = list(pool.map(outcome, zip(cases, folders)))
    bad = [(case, result) for case, result in results if result not in ("refused", "ran")]
    for case, result in bad:
        report(f"  {result}: {case.style}: {case.what}")
    refused = sum(result == "refused" for _, result in results)
    report(f"fuzz: {len(cases)} generated decks over {len(fuzz.STYLES)} command forms: {refused} malformed ones "
           f"refused with a LAMMPS error, {len(cases) - refused - len(bad)} valid ones ran, {len(bad)} wrong")
    assert not bad
