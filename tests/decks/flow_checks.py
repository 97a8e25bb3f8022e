# SPDX-License-Identifier: GPL-2.0-or-later
"""Deck tests of the two-way coupling (fix fluid/flow): registered with the others of checks.py
(harness.check), run as `python3 checks.py NAME [--np N]`."""
from __future__ import annotations

import math
import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

from harness import HERE, G, check, read_dump_frames, report, run_deck

try:    # (the harness puts python/ on the path)
    from sediment import _core
except ImportError:    # listing the checks, at configure time before the build, needs none
    _core = None


# ---- two-way coupling: fix fluid/flow ------------------------------------------------------------
CLOUD_DECK = HERE.parents[1] / "examples" / "falling_cloud" / "in.falling_cloud"


def cloud_result(np_ranks: int, tmp: Path, **variables) -> dict:
    return run_deck(CLOUD_DECK, variables, np_ranks, cwd=tmp).results


@check
def falling_cloud(np_ranks: int):
    """A spherical cloud of N spheres settles for N a / R >> 1 as a drop, U = U_s (1 + 6/5 N a / R)
    (Nitsche & Batchelor 1997), in the periodic box less Hasimoto's return flow, -2.837 N a U_s / L:
    the example deck, for N a / R = 5, 20 and 50 (a = R / 100: a dilute cloud, 0.5 % solids at most).
    The kernel (sigma = one cell) smooths the cloud's edge and its pair interactions, which slows it
    by about 2.2 (sigma / R)^2 (measured at R / sigma = 4, 6, 8, 12: 13.9, 6.3, 3.2, 0.8 % for N a / R = 20);
    the check extrapolates R / sigma = 4 and 6 (32 and 48 cells, box L = 8 R) to sigma -> 0 as
    (sigma / R)^2 and asks that within 3 % of the prediction: what remains is the random cloud's
    own spread (one seed), O((R / L)^3) = 0.4 % of the box and the O(a / d) discreteness."""
    worst = 0.0
    with tempfile.TemporaryDirectory() as tmp:
        for n, na_r in ((500, 5), (2000, 20), (5000, 50)):
            coarse = cloud_result(np_ranks, Path(tmp), n=n, na_r=na_r, cells=32)
            fine = cloud_result(np_ranks, Path(tmp), n=n, na_r=na_r, cells=48)
            extrapolated = fine["speed"] + (fine["speed"] - coarse["speed"]) / (1.5 ** 2 - 1)
            ratio = extrapolated / fine["predicted"]
            report(f"cloud N={n} Na/R={na_r}: U/U_s {coarse['speed'] / fine['us']:.3f} (R/sigma 4), "
                   f"{fine['speed'] / fine['us']:.3f} (R/sigma 6), extrapolated {extrapolated / fine['us']:.3f}; "
                   f"Nitsche & Batchelor {fine['drop'] / fine['us']:.3f}, with the box's return flow "
                   f"{fine['predicted'] / fine['us']:.3f}: ratio {ratio:.4f}; largest mean u_z over a plane "
                   f"{fine['flux']:.1e} m/s (grid's largest {fine['peak']:.1e})")
            worst = max(worst, abs(ratio - 1))
            # converging from below (the smoothing slows the cloud), and no net flux through any plane
            assert coarse["speed"] < fine["speed"] < 1.03 * fine["predicted"]
            assert abs(ratio - 1) < 0.03
            assert fine["flux"] < 1e-12 * fine["peak"] and coarse["flux"] < 1e-12 * coarse["peak"]
    report(f"falling cloud: worst extrapolated speed {worst:.2%} off the prediction")


@check
def flow_drift(np_ranks: int):
    """With `drift D` the fix solves once the spheres may have moved D cells (or their largest speed changed
    by the fraction D) since the last solve: a cloud of fine spheres (R = 1.5 mm, a = 15 um, N a / R = 10)
    over 650 steps of 16 tau settles at the speed it has with the flow solved every step, to 1e-4 (measured
    3.3e-5 over 1300 steps at D = 0.1), with a thirtieth of the solves or fewer."""
    with tempfile.TemporaryDirectory() as tmp:
        common = {"R": 1.5e-3, "n": 1000, "cells": 32, "steps": 650}
        every = cloud_result(np_ranks, Path(tmp), **common)
        drift = cloud_result(np_ranks, Path(tmp), **common, solve="drift 0.1")
    change = abs(drift["speed"] - every["speed"]) / every["speed"]
    report(f"cloud of fine spheres: every 1, {every['solves']:.0f} solves, speed {every['speed']:.6e} m/s; drift 0.1, "
           f"{drift['solves']:.0f} solves, speed {drift['speed']:.6e} m/s: relative change {change:.1e}")
    assert every["solves"] == common["steps"] + 5    # the setup's solve and one per step (4 + 650 steps)
    assert drift["solves"] * 30 <= every["solves"]
    assert change < 1e-4


def sphere_data(path: Path, title: str, positions: np.ndarray, types: np.ndarray, type_count: int,
                box: tuple[float, float, float], diameter: float, density: float, weight: float | None = None) -> None:
    """A data file of spheres of one diameter and density in a box from the origin; with `weight`, a
    Weights section giving each that many grains."""
    n = len(positions)
    atoms = np.column_stack([np.arange(1, n + 1), types, np.full(n, diameter), np.full(n, density), positions])
    with open(path, "w") as f:
        f.write(f"{title}\n\n{n} atoms\n{type_count} atom types\n\n0 {box[0]} xlo xhi\n0 {box[1]} ylo yhi\n"
                f"0 {box[2]} zlo zhi\n\nAtoms # sphere\n\n")
        np.savetxt(f, atoms, fmt=["%d", "%d", "%.17g", "%.17g", "%.17g", "%.17g", "%.17g"])
        if weight is not None:
            f.write("\nWeights\n\n")
            np.savetxt(f, np.column_stack([np.arange(1, n + 1), np.full(n, weight)]), fmt=["%d", "%.17g"])


def flow_data(path: Path, positions: np.ndarray, types: np.ndarray, box: tuple[float, float, float]) -> None:
    sphere_data(path, "settling cloud", positions, types, 2, box, 2e-4, 1100.0)


def cloud_positions(n: int, centre: tuple[float, float, float], radius: float, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    points = rng.uniform(-1, 1, (4 * n, 3))
    points = points[np.einsum("ij,ij->i", points, points) < 1][:n]
    return np.asarray(centre) + radius * points


@check
def flow_column_mirror(np_ranks: int):
    """The closed column (free slip at bottom and top by mirror images) is the periodic box twice as
    tall holding the spheres and their mirror images (which rise): the same state to round-off. The
    cloud sits near the bottom, so the bottom's image matters (it slows the cloud)."""
    height, side = 0.016, 0.016
    real = cloud_positions(300, (side / 2, side / 2, 0.25 * height), 0.003, 7)
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        flow_data(tmp / "column.data", real, np.ones(len(real)), (side, side, height))
        mirrored = real * [1, 1, -1] + [0, 0, 2 * height]
        flow_data(tmp / "mirror.data", np.vstack([real, mirrored]), np.r_[np.ones(len(real)), 2 * np.ones(len(real))],
                  (side, side, 2 * height))
        states = {}
        for mode in ("column", "mirror", "periodic"):
            data = tmp / ("column.data" if mode != "mirror" else "mirror.data")
            if mode == "periodic":    # the same cloud in a periodic box as tall as the column
                flow_data(tmp / "periodic.data", real, np.ones(len(real)), (side, side, height))
                data = tmp / "periodic.data"
            run_deck("fluid_flow.lmp", {"data": data, "mode": mode, "state": tmp / f"{mode}.txt", "phase": "whole"},
                     np_ranks, cwd=tmp)
            states[mode] = np.loadtxt(tmp / f"{mode}.txt", skiprows=9)
    column, mirror, periodic = states["column"], states["mirror"][: len(real)], states["periodic"]
    scale = np.abs(column[:, 4:10]).max()
    diff = float(np.abs(column[:, 4:10] - mirror[:, 4:10]).max() / scale)
    images = states["mirror"][len(real):]
    image_vz = float(images[:, 6].mean())
    report(f"column vs its explicit mirror image, {len(real)} spheres: max difference in v and u {diff:.1e} "
           f"(of {scale:.2e} m/s); mean v_z: column {column[:, 6].mean():.4e}, images {image_vz:.4e} (rising), "
           f"periodic box {periodic[:, 6].mean():.4e} m/s")
    assert diff < 1e-9
    assert abs(image_vz + column[:, 6].mean()) < 1e-9 * scale
    # the bottom slows the cloud against the periodic box of the same height
    assert column[:, 6].mean() > periodic[:, 6].mean()


@check
def flow_vessel_across(np_ranks: int):
    """A column is a sample of a vessel much wider than it: a force the same across its whole section
    (a sheet of 400 quartz spheres pushed along x at mid-height) moves no fluid uniform across
    (`across vessel`, a column's default). As a periodic array (`across periodic`) the sheet drags the
    infinitely wide plane: between free-slip ends H apart, with the mean flux removed, the fluid at the
    sheet moves at s H / (12 mu) (s the force per area), less s sigma / (mu sqrt(pi)) for the kernel
    (standard deviation sigma, spread and read: the kink at the sheet smoothed), 2.182 mm/s here; it
    read 2.171 mm/s, and the vessel's -1.8e-7 m/s. Such flows, of mobility up to (H / pi)^2 / mu, are
    what ran sample 3's tall column away from its third step (16 mm/s kicks uniform across)."""
    side, height, count, gravity, viscosity, sigma = 2e-3, 0.032, 400, 0.01, 1e-3, 0.25e-3
    box = quartz_box("p p f", (side, side, height),
                     f"region layer block 0 {side} 0 {side} {height / 2 - 5e-5} {height / 2 + 5e-5}\n"
                     f"create_atoms 1 random {count} 4242 layer")
    deck = box + f"""fix push all gravity {gravity} vector 1 0 0
fix water all fluid density 1000 viscosity {viscosity}
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law stokes
variable across index default
if "${{across}} == default" then "fix flow all fluid/flow water grid 8 8 128 column 0 {height} every 1" &
  else "fix flow all fluid/flow water grid 8 8 128 column 0 {height} every 1 across ${{across}}"
fix step all nve/sphere/fluid
compute ux all reduce ave f_flow[1]
thermo_style custom step c_ux
thermo 20
timestep 0.02
run 20
print "RESULT ux $(c_ux:%.17g)"
"""
    sheet = count * 1650 * gravity * math.pi / 6 * 1e-12 / side ** 2    # N/m2
    expected = sheet / viscosity * (height / 12 - sigma / math.sqrt(math.pi))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sheet.lmp"
        path.write_text(deck)
        outputs = {mode: run_deck(path, {"across": mode}, np_ranks, cwd=Path(tmp))
                   for mode in ("periodic", "default", "vessel")}
    ux = {mode: out.results["ux"] for mode, out in outputs.items()}
    # the log says which the fix solved, as the keyword or the column's default made it (once a run)
    for mode, held in (("periodic", False), ("default", True), ("vessel", True)):
        said = re.findall(r"fix flow fluid/flow: 8 x 8 x 128 cells of 0\.00025 m over the closed column z = 0 to "
                          r"0\.032 m \(transformed with its mirror image: 256 planes\)\n  the flow uniform across "
                          r"(held at rest \(across vessel\)|solved as in a periodic array \(across periodic\)); "
                          r"a solve every 1 steps", outputs[mode].text)
        assert said == ["held at rest (across vessel)" if held else "solved as in a periodic array (across periodic)"]
    report(f"fluid at the sheet: across periodic {ux['periodic']:.5g} m/s (expected {expected:.5g}), a column's "
           f"default {ux['default']:.2g} m/s, across vessel {ux['vessel']:.2g} m/s")
    assert ux["periodic"] == pytest.approx(expected, rel=0.02)
    assert abs(ux["default"]) < 1e-3 * expected and ux["vessel"] == ux["default"]


@check
def flow_unstable_lag(np_ranks: int):
    """A step far below the spheres' relaxation time with a strongly collective cloud (N a / R = 10,
    K about 12) makes the lagged flow reverse and grow from solve to solve: the run stops with an
    error naming relax (not a result gone wrong, nor atoms lost). relax below 1 / (1 + K) runs it."""
    deck = """units si
atom_style sphere
atom_modify map array
boundary p p p
region box block 0 0.048 0 0.048 0 0.048
create_box 1 box
region cloud sphere 0.024 0.024 0.024 0.006
create_atoms 1 random 1000 4321 cloud
set group all diameter 1.2e-4 density 1100
comm_modify cutoff 0.006
fix grav all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law stokes
fix flow all fluid/flow water grid 32 32 32 relax ${relax}
fix step all nve/sphere/fluid
timestep 8e-5
thermo 10
run 200
print "RESULT peak $(f_flow[5])"
"""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "lag.lmp"
        path.write_text(deck)
        out = run_deck(path, {"relax": 1}, np_ranks, expect_failure=True, cwd=Path(tmp))
        assert "the lagged flow is unstable at this time step; use relax" in out.text, out.error
        stable = run_deck(path, {"relax": 0.05}, np_ranks, cwd=Path(tmp))
        report(f"lagged flow at dt = tau / 10, K about 12: relax 1 stopped ({out.error.strip()[:90]}...); "
               f"relax 0.05 ran, largest fluid velocity {stable.results['peak']:.3g} m/s")
        assert 0 < stable.results["peak"] < 0.1



def quartz_box(boundary: str, box: tuple[float, float, float], atoms: str) -> str:
    """The opening of a deck of quartz spheres of 100 um in a box from the origin to `box` with `boundary`,
    created by the `atoms` lines (regions, create_atoms)."""
    return f"""units si
atom_style sphere
atom_modify map array
boundary {boundary}
region box block 0 {box[0]} 0 {box[1]} 0 {box[2]}
create_box 1 box
{atoms}
set group all diameter 1e-4
set group all density 2650
comm_modify cutoff 1e-4
"""


def quartz_deck(boundary: str, side: float, count: int, seed: int, drag: str, flow: str, integrator: str,
                run: str) -> str:
    """A deck of `count` quartz spheres of 100 um at random (seed) in a cubic box of `side` with
    `boundary`, falling in water under gravity and buoyancy, with the `drag` lines, fix fluid/flow's
    arguments after the fluid (`flow`), fix nve/sphere/fluid's keywords (`integrator`), then `run`."""
    return quartz_box(boundary, (side, side, side), f"create_atoms 1 random {count} {seed} NULL") + f"""fix fall all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy all fluid/buoyancy water
{drag}
fix flow all fluid/flow water {flow}
fix step all nve/sphere/fluid {integrator}
{run}"""

def run_with_state(deck: str, np_ranks: int):
    """Runs `deck`, which writes a dump to ${state}: its output and the dump's rows."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.lmp"
        path.write_text(deck)
        out = run_deck(path, {"state": Path(tmp) / "state.txt"}, np_ranks, cwd=Path(tmp))
        return out, np.loadtxt(Path(tmp) / "state.txt", skiprows=9)


@check
def flow_runaway(np_ranks: int):
    """A dense scene (6000 spheres of 100 um at 40 % solids, Richardson & Zaki, 9 cells a side) at a
    step where the flow carries them 3.2 cells between solves (dt 2e-2 s): the density the flow is
    solved from jumps, and the flow runs away without reversing (0.040, 0.038, 0.059 m/s, then 0.11
    and 0.36, when LAMMPS loses atoms on 2 ranks: the current LAMMPS reported them at step 6, before
    the tenfold growth over four solves that the fix stopped such runs at). The fix warns at the
    first such solve and stops the run once a solve carries the spheres across half the box, measured
    (drift) by how far the fastest sphere has moved: warned at step 2 (3.2 cells), stopped at step 4
    (4.9 cells of 9; by the grid's largest velocity, 5.3 cells at step 3). Not a result gone wrong, nor
    atoms lost. At dt 2e-3 s it runs, unwarned.
    (At 20 % solids this scene ran away the same way until the drag step took a jump of the fluid's
    velocity whole, DragBlock::relinearize_at_end; it now stays near 0.02 m/s, warned, until the
    flow's 1.7 cells a step lose atoms at step 10.)"""
    deck = quartz_deck(boundary="p p p", side=2e-3, count=6000, seed=777,
                       drag="compute conc all concentration/grid layers z 1\n"
                            "fix drag all fluid/drag water law stokes hindrance richardson-zaki concentration c_conc",
                       flow="grid 9 9 9", integrator="",
                       run="""thermo 1
timestep ${dt}
run 8
print "RESULT peak $(f_flow[5])"
""")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "dense.lmp"
        path.write_text(deck)
        out = run_deck(path, {"dt": 2e-2}, np_ranks, expect_failure=True, cwd=Path(tmp))
        assert re.search(r"WARNING: Fix fluid/flow: the flow carries spheres 3\.\d+ cells between solves \(1 steps of 0\.02 / cell "
                         r"0\.000222, the fastest sphere's path; step 2\)", out.text), \
            out.text[-2000:]
        assert "more than half the box across (9 cells" in out.text and "step 4)" in out.text, out.error
        calm = run_deck(path, {"dt": 2e-3}, np_ranks, cwd=Path(tmp))
    report(f"dense scene at dt 2e-2 s: warned, then stopped ({out.error.strip()[:100]}...); at dt 2e-3 s ran "
           f"unwarned, largest fluid velocity {calm.results['peak']:.3g} m/s")
    assert "carries spheres" not in calm.text and 0 < calm.results["peak"] < 0.05


@check
def flow_outside_column(np_ranks: int):
    """Spheres of the group that have left the column (fallen below its bottom, onto the box's floor)
    put no force on the fluid and see its uniform velocity (here at rest) exactly, with relax below 1
    too: relaxed towards it, they kept part of the grid's velocity from before they left (9.4e-4 m/s
    in the hostile round)."""
    deck = quartz_deck(boundary="p p f", side=4e-3, count=300, seed=4321,
                       drag="fix drag all fluid/drag water law stokes",
                       flow="grid 16 16 12 column 1e-3 4e-3 relax 0.1 every 1", integrator="floor z 0",
                       run="""timestep 1e-3
run 100
write_dump all custom ${state} id z f_flow[1] f_flow[2] f_flow[3] modify sort id format float %.17g
print "RESULT outside $(f_flow[6]) peak $(f_flow[5])"
""")
    out, rows = run_with_state(deck, np_ranks)
    outside = rows[rows[:, 1] < 1e-3]
    inside = rows[rows[:, 1] >= 1e-3]
    report(f"{len(outside)} spheres below the column (f_flow[6] {out.results['outside']:.0f}): largest fluid velocity "
           f"{np.abs(outside[:, 2:]).max():.1e} m/s; inside, up to {np.abs(inside[:, 2:]).max():.2e} m/s")
    assert len(outside) == out.results["outside"] > 50
    assert np.all(outside[:, 2:] == 0.0)
    assert np.abs(inside[:, 2:]).max() > 1e-4


@check
def flow_deposit(np_ranks: int):
    """Grains settling in a closed column onto the floor of fix nve/sphere/fluid at its bottom: those
    stopped on the floor are the deposit, which the flow leaves out (no force on the fluid, which they
    see at its uniform velocity, here at rest), as it leaves out grains below a column. Held on the
    floor whatever the fluid does, their drags could only resist the flow, and so stiffly that the
    flow grew from solve to solve from the first landings, at steps of 10 ms, 6.7 relaxation times (the
    build before: the grid's largest velocity 0.012, 0.047, 0.30, 2.2 m/s at steps 3 to 6, and the run
    stopped as a runaway at step 7)."""
    deck = quartz_deck(boundary="p p f", side=4e-3, count=1000, seed=2468,
                       drag="fix drag all fluid/drag water law stokes",
                       flow="grid 16 16 16 column 0 4e-3", integrator="floor z 0",
                       run="""timestep 1e-2
thermo 10
run 30
write_dump all custom ${state} id z vz f_flow[1] f_flow[2] f_flow[3] modify sort id format float %.17g
print "RESULT left_out $(f_flow[6]) peak $(f_flow[5])"
""")
    out, rows = run_with_state(deck, np_ranks)
    resting = (rows[:, 1] == 5e-5) & (rows[:, 2] == 0.0)
    report(f"{resting.sum()} of {len(rows)} grains at rest on the floor (f_flow[6] {out.results['left_out']:.0f}): "
           f"fluid velocity there {np.abs(rows[resting, 3:]).max():.1e} m/s; largest on the grid at the end "
           f"{out.results['peak']:.2e} m/s")
    assert out.results["left_out"] == resting.sum() > 300 and not np.all(resting)
    assert np.all(rows[resting, 3:] == 0.0)
    assert 0 < out.results["peak"] < 0.01


@check
def flow_step_limit(np_ranks: int):
    """Keyword cfl 0.5: 300 quartz grains of 100 um fall 2-4 mm onto the floor of a closed column (8 x 8 x
    32 cells of 0.125 mm) at an input step of 0.05 s, which would carry them 3.6 cells (the flow's
    warning at step 1, from rest). After each step the step is what carries the fastest fluid at a sphere
    half a cell at most (0.0106 s after the first step, 0.0053 at the flow's peak): exactly half where
    it changes, more than 0.5/1.2 where it is kept (it lengthens once it may grow by a fifth), and the
    time is the sum of the steps taken. Once the grains rest on the
    floor the flow stops and the step is the input's again. A timestep command gives a new longest
    step (in a run with pre no too); a run after a run keeps the last one; a run resumed from a restart
    file takes the same steps, also when its deck gives the same timestep again. With every 2 the run
    goes on at shortened steps (it stopped at its first solve, measured by the new flow: 5.3 cells)."""
    fixes = """fix fall all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law stokes
fix flow all fluid/flow water grid 8 8 32 column 0 4e-3 cfl 0.5
fix step all nve/sphere/fluid floor z 0
fix show all print 1 "STEP $(step) $(dt:%.17g) $(time:%.17g) $(f_flow[6])" screen yes
"""
    deck = quartz_box("p p f", (1e-3, 1e-3, 4e-3), """region top block 0 1e-3 0 1e-3 2e-3 3.9e-3
create_atoms 1 random 300 2468 top""") + fixes + """restart 30 limit.*.restart
dump u all custom 1 u.txt id f_flow[1] f_flow[2] f_flow[3]
dump_modify u format float %.17g
timestep 0.05
run 60
undump u
timestep 0.02
run 5
timestep 0.03
run 5 pre no
"""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "limit.lmp"
        path.write_text(deck)
        out = run_deck(path, {}, np_ranks, cwd=Path(tmp))
        frames = read_dump_frames(Path(tmp) / "u.txt")
        # resumed from step 30's restart file (a step the fix kept as the flow slowed), the input's step
        # given again as a resumed deck's stage does: the steps as before
        path.write_text("read_restart limit.30.restart\ncomm_modify cutoff 1e-4\n" + fixes + "timestep 0.05\nrun 30\n")
        resumed = step_rows(run_deck(path, {}, np_ranks, cwd=Path(tmp)).text)
        # solved every 2 steps: the flow that moved the spheres, not the one just solved, is what the
        # run-away check measures, and the steps shorten from the first solve
        # (and a new longest step given to a run with pre no: its first shortening is reported too)
        path.write_text(deck.replace("cfl 0.5", "every 2 cfl 0.5").split("restart 30")[0]
                        + "timestep 0.05\nrun 30\ntimestep 0.006\nrun 2 pre no\n")
        every_text = run_deck(path, {}, np_ranks, cwd=Path(tmp)).text
        every = step_rows(every_text)
    rows = step_rows(out.text)
    cell = 1e-3 / 8
    fastest = {step: float(np.linalg.norm(frame[:, 1:], axis=1).max()) for step, frame in frames.items()}
    carried = np.array([fastest[n] * rows[n][0] / cell for n in range(1, 61)])    # cells in the next step
    shortened = np.array([rows[n][0] < 0.05 for n in range(1, 61)])
    report(f"cfl 0.5: the next step carries the fastest fluid at a sphere {carried.max():.12f} cells at most, "
           f"{carried[shortened].min():.12f} where shortened ({shortened.sum()} steps; from {rows[1][0]:.4g} s, "
           f"shortest {min(rows[n][0] for n in range(61)):.4g} s); at step 60 {rows[60][2]:.0f} grains on the floor, "
           f"step {rows[60][0]:g} s; after timestep 0.02 and 0.03 (pre no): {rows[65][0]:g} and {rows[70][0]:g} s; "
           f"every 2: {every[2][0]:.4g} s after its first solve")
    assert "shortened from 0.05 to 0.0106" in out.text
    changed = np.array([rows[n][0] != rows[n - 1][0] for n in range(1, 61)])
    assert np.all(carried <= 0.5 * (1 + 1e-12)) and np.all(np.abs(carried[shortened & changed] - 0.5) < 1e-9)
    assert np.all(carried[shortened] > 0.5 / 1.2 * (1 - 1e-12))    # lengthened once it may grow by a fifth
    assert shortened[:30].all() and rows[60][0] == 0.05 and rows[60][2] == 300
    times = np.array([rows[n][1] for n in range(61)])
    steps = np.array([0.05] + [rows[n][0] for n in range(60)])
    assert np.allclose(np.diff(times), steps[1:], rtol=1e-12, atol=0)
    assert rows[65][0] == 0.02 and rows[70][0] == 0.03    # a timestep command gives the longest, pre no too
    assert every[2][0] < 0.006 and max(every[n][0] for n in range(2, 31)) < 0.05 and len(every) == 33
    assert "step 32 shortened from 0.006 to" in every_text    # (every 2: the fix acts at even steps)
    # (the time is not compared: LAMMPS 2021's restart files do not keep it; fix layers/hdf5 does)
    assert all(resumed[n][0] == pytest.approx(rows[n][0], rel=1e-12) and resumed[n][2] == rows[n][2]
               for n in range(30, 61))


def step_rows(text: str) -> dict[int, tuple[float, float, float]]:
    """The `STEP step dt time left-out` rows a deck prints, by step (a run's setup repeats the last)."""
    rows: dict[int, tuple[float, float, float]] = {}
    for line in text.splitlines():
        if line.startswith("STEP "):
            step, *values = line.split()[1:]
            rows.setdefault(int(step), tuple(float(v) for v in values))
    return rows


def spread_forces(deck: str, np_ranks: int) -> np.ndarray:
    """Runs `deck`, which prints `FORCE step f_flow[3] f_flow[6] ...` at each step: those rows' numbers."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "budget.lmp"
        path.write_text(deck)
        out = run_deck(path, {}, np_ranks, cwd=Path(tmp))
    return np.array([[float(v) for v in line.split()[1:]] for line in out.text.splitlines()
                     if line.startswith("FORCE ")])


@check
def flow_momentum(np_ranks: int):
    """What the spheres put on the fluid is what the fluid took from them: at steps of 7 and 36
    relaxation times each sphere's drag over a step is its weight less its buoyancy, and the force
    spread at each solve (f_flow[3]) is their sum over the spheres whose force the solve takes (all but
    f_flow[6]), to 1e-4.
    - 300 grains fall through a layer of 1500 held ones (fraction 0.39, Richardson & Zaki). The
      integrator steps a grain with the local fraction of the step's start, refreshed only after the
      step; the solve takes its drag with that fraction (4.4e-5 measured). The build before took it
      anew with the fraction the grain had reached, more than its weight for one entering the layer at
      speed and less for one leaving it: the sum was off by -2.5 % to +15.5 % from step 6 (in sample
      5's column at 100 g/L such parcels, entering the deposit's dense top, spread 18 times their
      force of the step before).
    - 300 spheres lighter than water rise to the surface of fix nve/sphere/fluid, which holds them
      there: held, they push the surface and spread nothing; those still rising spread their buoyancy
      less their weight (exactly, under Stokes's law). Turned back by fix wall/reflect instead, they
      spread 1.0095-1.038 of it, the reflected velocity taken into their next drag."""
    bed = quartz_box("p p f", (2e-3, 2e-3, 4e-3), """region layer block 0 2e-3 0 2e-3 1.5e-3 2e-3
region above block 0 2e-3 0 2e-3 2.2e-3 3.9e-3
create_atoms 1 random 1500 2468 layer
create_atoms 1 random 300 1357 above
group falling id > 1500""") + """fix fall falling gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy falling fluid/buoyancy water
compute conc all concentration/grid layers z 16 bounds 0 4e-3
fix drag falling fluid/drag water law stokes hindrance richardson-zaki concentration c_conc
fix flow falling fluid/flow water grid 8 8 16 column 0 4e-3 every 1
fix step falling nve/sphere/fluid floor z 0
fix budget all print 1 "FORCE $(step) $(f_flow[3]:%.12g) $(f_flow[6]) $(count(falling,layer))" screen yes
timestep 1e-2
run 40
"""
    surface = quartz_box("p p f", (2e-3, 2e-3, 2e-3), """region top block 0 2e-3 0 2e-3 1.6e-3 1.95e-3
create_atoms 1 random 300 4321 top""") + """set group all density 500
fix fall all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy all fluid/buoyancy water
fix drag all fluid/drag water law stokes
fix flow all fluid/flow water grid 8 8 8 column 0 2e-3 every 1
fix step all nve/sphere/fluid surface z 2e-3
fix budget all print 1 "FORCE $(step) $(f_flow[3]:%.12g) $(f_flow[6])" screen yes
timestep 1e-2
run 40
"""
    volume = math.pi / 6 * 1e-4 ** 3
    for name, rows, excess_density in (("grains through a held layer", spread_forces(bed, np_ranks), 2650 - 1000),
                                       ("light spheres under the surface", spread_forces(surface, np_ranks), 500 - 1000)):
        taken = 300 - rows[:, 2]
        free = (rows[:, 0] >= 5) & (taken > 0)    # from rest, the first steps also accelerate the spheres
        ratio = rows[free, 1] / (-excess_density * volume * G * taken[free])    # weight less buoyancy, down
        report(f"{name}: force spread over the weight less buoyancy of the spheres it takes, steps 5-40: "
               f"{ratio.min():.6f} to {ratio.max():.6f}; spheres left out at steps 10, 20, 40: "
               f"{rows[10, 2]:.0f}, {rows[20, 2]:.0f}, {rows[40, 2]:.0f}")
        assert len(rows) == 41 and free.sum() >= 8 and np.all(np.abs(ratio - 1.0) < 1e-4)
        assert rows[10, 2] < rows[40, 2]
    assert rows[40, 2] == 300 and rows[40, 1] == 0.0    # all held: nothing spread


@check
def flow_unmoved(np_ranks: int):
    """What changes the flow without moving the spheres, under the default schedule (drift), which
    otherwise watches their motion:
    - the fluid given a uniform velocity between runs: spheres at rest in still water (no gravity)
      take it at the next run's first step (the build before: they kept 0, and the fix never solved
      again);
    - spheres of the flow that no integrator moves (a fixed bed) in a stream: their drags depend on
      the fluid velocity the last solve gave them, so the fix solves again while a solve changes it
      by more than half the drift fraction. At relax 1 the lagged iteration diverges and stops with
      the error naming relax, as with every 1; at relax 0.3 it comes within a tenth of the
      converged disturbance (the build before: the bed's mean fluid velocity 0.00932 m/s after its one
      solve, against 0.01077 solved every step)."""
    moving = quartz_deck(boundary="p p p", side=4e-3, count=20, seed=2468,
                         drag="fix drag all fluid/drag water law stokes", flow="grid 16 16 16", integrator="",
                         run="""fix fall all gravity 0 vector 0 0 -1
timestep 1e-3
run 10
fix water all fluid density 1000 viscosity 1e-3 velocity 0.01 0 0
run 10
print "RESULT vx $(vcm(all,x):%.17g) solves $(f_flow[7])"
""")
    bed = quartz_deck(boundary="p p p", side=2e-3, count=400, seed=97, drag="fix drag all fluid/drag water law stokes",
                      flow="grid 16 16 16 ${schedule}", integrator="", run="""fix fall all gravity 0 vector 0 0 -1
unfix step
fix water all fluid density 1000 viscosity 1e-3 velocity 0.01 0 0
compute ux all reduce ave f_flow[1]
thermo_style custom step c_ux f_flow[7]
timestep 1e-3
run 60
print "RESULT ux $(c_ux:%.17g) solves $(f_flow[7])"
""")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        (tmp / "moving.lmp").write_text(moving)
        (tmp / "bed.lmp").write_text(bed)
        stream = run_deck(tmp / "moving.lmp", {}, np_ranks, cwd=tmp).results
        diverged = run_deck(tmp / "bed.lmp", {"schedule": ""}, np_ranks, expect_failure=True, cwd=tmp)
        relaxed = run_deck(tmp / "bed.lmp", {"schedule": "relax 0.3"}, np_ranks, cwd=tmp).results
        converged = run_deck(tmp / "bed.lmp", {"schedule": "relax 0.3 every 1"}, np_ranks, cwd=tmp).results
    disturbance = converged["ux"] - 0.01
    report(f"spheres at rest, the fluid given 0.01 m/s between runs: their mean velocity {stream['vx']:.6g} m/s after "
           f"10 steps ({stream['solves']:.0f} solves); a fixed bed in a stream: relax 1 stopped "
           f"({diverged.error.strip()[:60]}...), relax 0.3 mean fluid velocity {relaxed['ux']:.7g} m/s in "
           f"{relaxed['solves']:.0f} solves, every step {converged['ux']:.7g} ({converged['solves']:.0f} solves)")
    assert 0.009 < stream["vx"] <= 0.01
    assert "the lagged flow is unstable at this time step; use relax" in diverged.text
    assert abs(disturbance) > 1e-4 and abs(relaxed["ux"] - converged["ux"]) < 0.1 * abs(disturbance)
    assert relaxed["solves"] < converged["solves"]


def hard_sphere_suspension(n: int, phi: float, d: float, seed: int) -> tuple[np.ndarray, float]:
    """n spheres of diameter d at solid fraction phi in a periodic cube, placed one by one at random
    where they overlap none placed before (random sequential addition): positions and the side."""
    side = (n * math.pi / 6 * d ** 3 / phi) ** (1 / 3)
    cells = max(1, int(side // d))
    width = side / cells
    rng = np.random.default_rng(seed)
    placed: list[np.ndarray] = []
    bins: dict[tuple[int, int, int], list[int]] = {}
    offsets = [(a, b, c) for a in (-1, 0, 1) for b in (-1, 0, 1) for c in (-1, 0, 1)]
    while len(placed) < n:
        point = rng.uniform(0.0, side, 3)
        home = tuple(int(v) % cells for v in point // width)
        near = [j for o in offsets for j in bins.get(tuple((h + k) % cells for h, k in zip(home, o)), [])]
        if near:
            gap = np.asarray([placed[j] for j in near]) - point
            gap -= side * np.round(gap / side)
            if np.einsum("ij,ij->i", gap, gap).min() < d * d:
                continue
        bins.setdefault(home, []).append(len(placed))
        placed.append(point)
    return np.asarray(placed), side


def suspension_data(path: Path, positions: np.ndarray, side: float, d: float, weight: float = 1.0) -> None:
    """A data file of quartz spheres of diameter d in a periodic cube, each standing for `weight` grains."""
    sphere_data(path, "suspension", positions, np.ones(len(positions)), 1, (side, side, side), d, 2650.0, weight)


@check
def suspension_flow(np_ranks: int):
    """A homogeneous suspension (hard spheres at random, 0.5-5 % solids) under Richardson & Zaki's
    hindrance settles as fast with the flow it drives (fix fluid/flow) as without: the grid's flow
    averages to nothing over a homogeneous suspension but for each sphere's own force and images and
    the neighbours kept clear of it, which the closure takes out (docs/physics.md section 8), so the
    suspension is not hindered twice. Without the closure (the unbounded self-flow subtracted, as
    before it) the same suspensions settled 2.6, 3.4, 4.4 and 8.1 % too slowly. One configuration's mean speed
    varies by about 1.5 % with the box-scale fluctuation of its density (the flow of a box-scale
    density wave, which the grid resolves); the mean over 6 configurations is within 1 % of the
    hindered speed without flow, and each within 5 %."""
    d, n, seeds = 2e-5, 2000, range(1, 7)
    hindered = _core.DragModel("stokes", 1000.0, 1e-3, hindrance="richardson-zaki")
    weight = 1650.0 * G * math.pi / 6 * d ** 3
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for phi in (0.005, 0.01, 0.02, 0.05):
            expected = hindered.steady_speed(d, weight, 1 - phi)[0]
            ratios = []
            for seed in seeds:
                suspension_data(tmp / "suspension.data", *hard_sphere_suspension(n, phi, d, seed), d)
                out = run_deck("suspension_flow.lmp", {"data": tmp / "suspension.data", "cells": 8}, np_ranks, cwd=tmp)
                assert abs(out.results["phi"] - phi) < 1e-9
                ratios.append(out.results["speed"] / expected)
            mean = float(np.mean(ratios))
            report(f"suspension phi={phi}: speed with flow / Richardson & Zaki's {mean:.4f} over {len(ratios)} "
                   f"configurations (each {min(ratios):.4f} to {max(ratios):.4f}, standard error "
                   f"{np.std(ratios, ddof=1) / math.sqrt(len(ratios)):.4f})")
            assert abs(mean - 1) < 0.01
            assert max(abs(r - 1) for r in ratios) < 0.05


@check
def flow_parcels(np_ranks: int):
    """Parcels stir a suspension as its real grains do. 2000 grains of 20 um at 2 % in a periodic box
    (hard spheres at random), against 250 parcels of 8 grains placed independently (`weight d_weight`:
    each puts sqrt(8 S(0)) times its grain's drag on the fluid), 300 steps of 0.05 s, 8
    configurations each. The variance of the grains' vertical velocity, the velocity fluctuations of
    the box-scale swirls, agrees within a third: 0.83 (standard errors 14-17 % on each side; with 4000
    grains and 12 configurations, 0.84). Without the weight the parcels' variance was 8 times too
    small (1.6e-9 against 1.6e-8 m2/s2 at 4000 grains, 8 configurations), and with the parcels' whole
    force w F it would be 8 times too large. The mean speeds agree within 1 %."""
    d, n, phi, w = 2e-5, 2000, 0.02, 8
    run = {"cells": 8, "steps": 300, "dt": 0.05}
    side = (n * math.pi / 6 * d ** 3 / phi) ** (1 / 3)
    results = {"grains": [], "parcels": []}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for seed in range(1, 9):
            suspension_data(tmp / "grains.data", *hard_sphere_suspension(n, phi, d, seed), d)
            parcels = np.random.default_rng(seed).uniform(0.0, side, (n // w, 3))
            suspension_data(tmp / "parcels.data", parcels, side, d, w)
            for kind, parcels_flag in (("grains", "no"), ("parcels", "yes")):
                out = run_deck("suspension_flow.lmp", {"data": tmp / f"{kind}.data", "parcels": parcels_flag, **run},
                               np_ranks, cwd=tmp)
                assert abs(out.results["phi"] - phi) < 1e-9
                results[kind].append((out.results["speed"], out.results["variance"]))
    stats = {}
    for kind, rows in results.items():
        speed, variance = np.array(rows).T
        stats[kind] = (speed.mean(), variance.mean(), variance.std(ddof=1) / math.sqrt(len(variance)))
        report(f"{kind}: mean speed {speed.mean():.6g} m/s, vertical velocity variance {variance.mean():.4g} "
               f"+- {stats[kind][2]:.2g} m2/s2 (8 configurations)")
    ratio = stats["parcels"][1] / stats["grains"][1]
    report(f"parcels of {w} / real grains: variance {ratio:.3f}, mean speed {stats['parcels'][0] / stats['grains'][0]:.4f}")
    assert 2 / 3 < ratio < 3 / 2
    assert stats["parcels"][0] == pytest.approx(stats["grains"][0], rel=0.01)


def stratified_positions(n: int, side: float, top: float, rng: np.random.Generator) -> np.ndarray:
    """n points in a column of square section `side`, their density falling linearly from the floor to zero
    at `top`, placed independently."""
    z = top * (1.0 - np.sqrt(1.0 - rng.uniform(0.0, 1.0, n)))
    return np.column_stack([rng.uniform(0.0, side, n), rng.uniform(0.0, side, n), z])


@check
def flow_stratified(np_ranks: int):
    """A stably stratified column restores as its real grains do with `stratification grains`. 7162
    grains of 20 um (2 % solids at the floor falling linearly to none 3 mm up, a column 1 x 1 x 4 mm on
    8 x 8 x 32 cells) against 265 parcels of 27 placed independently, 16 configurations each: the flow
    the random start drives is damped as it displaces the stratification, and the variance of the
    spheres' vertical velocity falls from 0.2 s to 1.6 s at a mean rate of 1.67 /s for the grains,
    1.31 /s for the parcels with `stratification grains` and 0.62 /s with their own forces alone
    (`parcels`, which give the displaced profile sqrt(27) of 27 grains' force). The ratio of the first
    two, 0.79, has a standard error of 0.06 (both rates' over the configurations); the band 0.7-1.2
    takes it within that and fails the parcels' own 0.37, the option's force halved (0.66) or its sign
    reversed (-0.72: the flow grows)."""
    d, phi0, top, side, height, w = 2e-5, 0.02, 3e-3, 1e-3, 4e-3, 27
    n = int(round(side * side * phi0 * top / 2 / (math.pi / 6 * d ** 3)))
    run = {"steps": 4, "rounds": 8, "dt": 0.05}
    kinds = {"grains": {}, "parcels": {"parcels": "yes"},
             "stratification grains": {"parcels": "yes", "stratification": "grains"}}
    rates: dict[str, list[float]] = {kind: [] for kind in kinds}
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        for seed in range(1, 17):
            rng = np.random.default_rng(seed)
            box = (side, side, height)
            sphere_data(tmp / "grains.data", "grains", stratified_positions(n, side, top, rng), np.ones(n), 1, box, d,
                        2650.0, 1.0)
            sphere_data(tmp / "parcels.data", "parcels", stratified_positions(n // w, side, top, rng),
                        np.ones(n // w), 1, box, d, 2650.0, float(w))
            for kind, variables in kinds.items():
                data = tmp / ("grains.data" if kind == "grains" else "parcels.data")
                out = run_deck("stratified_flow.lmp", {"data": data, **run, **variables}, np_ranks, cwd=tmp)
                first, last = out.results["variance1"], out.results[f"variance{run['rounds']}"]
                elapsed = (run["rounds"] - 1) * run["steps"] * run["dt"]
                rates[kind].append(math.log(first / last) / elapsed)
    stats = {kind: (float(np.mean(r)), float(np.std(r, ddof=1) / math.sqrt(len(r)))) for kind, r in rates.items()}
    for kind, (mean, error) in stats.items():
        report(f"{kind}: the vertical velocity's variance falls at {mean:.3f} +- {error:.3f} /s (16 configurations)")
    grains = stats["grains"][0]
    report(f"over the grains' rate: stratification grains {stats['stratification grains'][0] / grains:.3f}, "
           f"parcels {stats['parcels'][0] / grains:.3f}")
    assert 0.7 < stats["stratification grains"][0] / grains < 1.2
    assert stats["parcels"][0] / grains < 0.5


@check
def flow_stratified_restart(np_ranks: int):
    """`stratification grains` keeps each sphere's excess and the classes' profiles: 2 x 8 steps in one run
    against 8, write_restart, read_restart in a new process and 8 more give the same spheres and flow to
    round-off (the excesses lost, the second half's restoring force would start from none; the profiles
    lost, the steps before the first solve would add none)."""
    d, side, top, height, w = 2e-5, 1e-3, 3e-3, 4e-3, 27
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        positions = stratified_positions(265, side, top, np.random.default_rng(5))
        sphere_data(tmp / "parcels.data", "parcels", positions, np.ones(len(positions)), 1, (side, side, height), d,
                    2650.0, float(w))
        common = {"data": tmp / "parcels.data", "parcels": "yes", "stratification": "grains", "steps": 8, "rounds": 1,
                  "restart": tmp / "stratified.restart"}
        run_deck("stratified_flow.lmp", {**common, "phase": "both", "state": tmp / "whole.txt"}, np_ranks, cwd=tmp)
        run_deck("stratified_flow.lmp", {**common, "phase": "first"}, np_ranks, cwd=tmp)
        run_deck("stratified_flow.lmp", {**common, "phase": "second", "state": tmp / "split.txt"}, np_ranks, cwd=tmp)
        whole, split = np.loadtxt(tmp / "whole.txt", skiprows=9), np.loadtxt(tmp / "split.txt", skiprows=9)
    flow = np.abs(whole[:, 7:10]).max()
    diff = float(np.abs(whole[:, 7:10] - split[:, 7:10]).max())
    report(f"stratified restart: {len(whole)} parcels, fluid velocity split vs whole max difference {diff:.1e} "
           f"(up to {flow:.1e} m/s); positions {float(np.abs(whole[:, 1:4] - split[:, 1:4]).max()):.1e} m apart")
    assert whole.shape == split.shape and diff <= 1e-9 * flow
    assert np.abs(whole[:, 1:4] - split[:, 1:4]).max() <= 1e-12 * height


@check
def flow_bed(np_ranks: int):
    """Grains without contacts pile up on the floor: the concentration grid's fraction there passes any
    packing, the hindrance is capped (max_fraction 0.64), and those grains, held to the fluid by the
    capped drag, stirred it as a suspension far denser than a bed. In sample 2's column of parcels
    13 000 of them churned within 2 mm of the floor at 1-2.5 mm/s for minutes. Past the cap a grain is
    in the bed: the flow leaves it out, as it does the deposit at rest on the floor. Here 1500 grains of
    100 um piled in the bottom layer and 200 above: f_flow[6] counts those whose fraction is past the
    cap (1292 of the pile), whose fluid velocity is the uniform one (at rest) exactly, and only they
    (the build before: none)."""
    deck = quartz_box("p p f", (2e-3, 2e-3, 4e-3), """region bed block 0 2e-3 0 2e-3 0.06e-3 0.19e-3
region above block 0 2e-3 0 2e-3 1e-3 3.9e-3
create_atoms 1 random 1500 2468 bed
create_atoms 1 random 200 1357 above""") + """fix fall all gravity 9.81 vector 0 0 -1
fix water all fluid density 1000 viscosity 1e-3
fix buoy all fluid/buoyancy water
compute conc all concentration/grid layers z 16 bounds 0 4e-3
fix drag all fluid/drag water law stokes hindrance richardson-zaki concentration c_conc
fix flow all fluid/flow water grid 8 8 16 column 0 4e-3
fix step all nve/sphere/fluid floor z 0
timestep 1e-4
run 3
write_dump all custom ${state} id z f_flow[1] f_flow[2] f_flow[3] c_conc modify sort id format float %.17g
print "RESULT left_out $(f_flow[6])"
"""
    out, rows = run_with_state(deck, np_ranks)
    capped = rows[:, 5] > 0.64
    report(f"fractions the grains read: {rows[:1500, 5].min():.3f}-{rows[:1500, 5].max():.3f} in the pile, up to "
           f"{rows[1500:, 5].max():.3f} above; {capped.sum()} past the cap, left out {out.results['left_out']:.0f}: "
           f"their fluid velocity up to {np.abs(rows[capped, 2:5]).max():.1e} m/s, the others' "
           f"{np.abs(rows[~capped, 2:5]).min():.1e} to {np.abs(rows[~capped, 2:5]).max():.2e} m/s")
    assert out.results["left_out"] == capped.sum() > 1000 and not capped[1500:].any()
    assert np.all(rows[capped, 2:5] == 0.0) and np.all(np.abs(rows[~capped, 2:5]).max(axis=1) > 0)


PARCEL_IMAGE_DECK = quartz_box("p p f", (4e-3, 4e-3, 8e-3), "create_atoms 1 single 2.125e-3 2.125e-3 ${z}") + """fix weights all property/atom d_weight
set group all d_weight ${weight}
fix water all fluid density 1000 viscosity 1e-3
fix drag all fluid/drag water law stokes
fix flow all fluid/flow water grid 16 16 32 column 0 8e-3 weight d_weight
fix step all nve/sphere/fluid
velocity all set 0 0 -1e-2
run 0
write_dump all custom ${state} id z vz f_flow[1] f_flow[2] f_flow[3] modify format float %.17g
"""


@check
def flow_parcel_image(np_ranks: int):
    """In a closed column a sphere's force has a mirror image, which a parcel stirs with sqrt(w) grains'
    force as it does its own. The parcel moves as one grain, so it must meet one grain's image, as it
    does not meet its own flow: a lone parcel of 1e5 grains of 100 um settling at 1 cm/s half a cell
    from the top or the bottom (cells of 0.25 mm) reads the fluid velocity that a lone grain reads there
    (0.72 mm/s up, 7 % of its speed: the free surface and the floor slow it). Where the grid's nodes
    are, to round-off; off them within a third (the image's flow is tabulated at 1/8 cell, and what
    the kernel gives a sphere back off a node differs from at a node; 28 % measured). The build before
    gave the parcel sqrt(1e5) = 316 times the grain's image: 0.23 m/s up, which lifts a fine parcel
    to the surface, and parcels of fine grains hovered above the floor and ran sample 2's column away
    at the surface within 30 s. In the middle the image is gone (5e-5 of it)."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "image.lmp"
        path.write_text(PARCEL_IMAGE_DECK)
        read = {}
        for z in (7.875e-3, 1.25e-4, 2e-4, 4.125e-3):
            for weight in (1, 1e5):
                state = Path(tmp) / "state.txt"
                run_deck(path, {"z": z, "weight": weight, "state": state}, np_ranks, cwd=Path(tmp))
                read[z, weight] = np.loadtxt(state, skiprows=9)[5]
    for z, on_node in ((7.875e-3, True), (1.25e-4, True), (2e-4, False)):
        grain, parcel = read[z, 1], read[z, 1e5]
        report(f"z = {z * 1e3:g} mm: the fluid velocity a grain reads {grain:.6e} m/s, a parcel of 1e5 {parcel:.6e} m/s "
               f"(ratio {parcel / grain:.6f})")
        assert 5e-4 < grain < 1e-3
        assert parcel == pytest.approx(grain, rel=1e-9 if on_node else 1 / 3)
    middle = read[4.125e-3, 1e5]
    report(f"mid-column: a parcel of 1e5 reads {middle:.2e} m/s")
    assert abs(middle) < 1e-4 * read[1.25e-4, 1]


@check
def flow_restart(np_ranks: int):
    """2N steps in one run vs N steps + write_restart + read_restart in a new process + N steps: the
    per-atom fluid velocity comes back with the restart, so the flow carries on as if never stopped."""
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        flow_data(tmp / "cloud.data", cloud_positions(400, (0.008, 0.008, 0.008), 0.003, 3), np.ones(400),
                  (0.016, 0.016, 0.016))
        common = {"data": tmp / "cloud.data", "restart": tmp / "flow.restart"}
        whole_run = run_deck("fluid_flow.lmp", {**common, "phase": "whole", "state": tmp / "whole.txt"}, np_ranks,
                             cwd=tmp)
        run_deck("fluid_flow.lmp", {**common, "phase": "first"}, np_ranks, cwd=tmp)
        split_run = run_deck("fluid_flow.lmp", {**common, "phase": "second", "state": tmp / "split.txt"}, np_ranks,
                             cwd=tmp)
        whole, split = np.loadtxt(tmp / "whole.txt", skiprows=9), np.loadtxt(tmp / "split.txt", skiprows=9)
    scale = np.abs(whole[:, 4:10]).max()
    diff = float(np.abs(whole[:, 1:] - split[:, 1:]).max())
    report(f"flow restart: {len(whole)} spheres, split vs whole max difference {diff:.1e} (speeds up to {scale:.1e} m/s); "
           f"the last solve's diagnostics {whole_run.results} and {split_run.results}")
    assert whole.shape == split.shape and diff <= 1e-12 * max(scale, 1e-3)
    # the diagnostics of the last solve come back too (the default schedule need not solve again soon)
    # (the net flux is round-off, which another decomposition's sums change)
    assert split_run.results == pytest.approx(whole_run.results, rel=1e-9, abs=1e-12 * whole_run.results["peak"])


@check(ranks=())
def flow_ranks(np_ranks: int):
    """The falling cloud on 1 and 2 ranks: the same speed to round-off (the reduce-scatter and the
    FFT's remaps sum in another order)."""
    with tempfile.TemporaryDirectory() as tmp:
        one, two = (cloud_result(ranks, Path(tmp), n=1000, cells=32)["speed"] for ranks in (1, 2))
    report(f"cloud speed on 1 rank {one!r}, on 2 ranks {two!r}: relative difference {abs(one - two) / one:.1e}")
    assert abs(one - two) < 1e-10 * one


@check
def flow_new_sphere(np_ranks: int):
    """A sphere created between runs (as by create_atoms, fix deposit or pour) takes the fluid
    velocity of the last solve where it is: bit for bit a tracer's at that place (in the flow's group,
    without drag or weight: it reads the grid at each solve and pushes nothing). Not the row a deleted
    sphere left behind (a grain's, rising where the fluid sinks), nor the unit force's flow a run's init
    leaves on the grid when it measures the kernel's self-flow, nor a freed fluid fix's velocity (the
    fluid is redefined before; the sanitizer's build would stop at the read). The flow fix, defined
    before its fluid, takes spheres created in between; and a sphere of the flow's group outside the
    drag's, whose speed squared overflows, pushes nothing: the grid stays finite."""
    with tempfile.TemporaryDirectory() as tmp:
        out = run_deck("flow_new_sphere.lmp", {"state": Path(tmp) / "state.txt"}, np_ranks, cwd=Path(tmp))
        rows = {int(row[0]): row[1:] for row in np.loadtxt(Path(tmp) / "state.txt", skiprows=9)}
    peak = float(next(line for line in out.text.splitlines() if line.startswith("RESULT ")).split()[2])
    tracer, new = rows[1], rows[403]    # x y z ux uy uz
    report(f"new sphere's fluid velocity {list(new[3:])} m/s; the tracer's at the same place {list(tracer[3:])} "
           f"(grid's largest {peak:.2e} m/s)")
    assert math.isfinite(peak) and all(np.isfinite(row).all() for row in rows.values())
    assert list(new[:3]) == list(tracer[:3])
    assert list(new[3:]) == list(tracer[3:])
    assert 0.1 * peak < abs(tracer[5]) <= peak    # the local flow, not the fluid at rest
