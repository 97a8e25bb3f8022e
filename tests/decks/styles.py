# SPDX-License-Identifier: GPL-2.0-or-later
"""One small scene per SEDIMENT style, and the two checks every style gets from it (in the spirit of
LAMMPS's unittest/force-styles):

* regression: the final per-atom state (x, v, omega) and the style's own outputs after N steps at
  dt and N at dt / 2 agree with the values pinned in tests/data/reference/style_<name>.json;
* replay: the same run split by write_restart / read_restart in a new process, with the time step
  changed after the restart, ends in the same state and outputs.

A new style gets both by adding a `Scene` here and pinning its reference once:
    python3 tests/decks/checks.py style_<name> --regenerate
"""
from __future__ import annotations

import json
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from harness import HERE, report, run_deck

REFERENCES = HERE.parent / "data" / "reference"

# Regression tolerance, relative to the scale of each quantity (box size, largest speed, largest spin,
# largest output): the references are serial runs; 2 ranks sum forces and grids in another order
# (1e-15 per step, grown by contacts over the run), while any change of a formula, a constant or
# the step moves these values by 1e-6 or more.
REGRESSION_TOLERANCE = 1e-9
# A split run re-sorts and re-neighbours the atoms at the restart: the same order-of-summation noise.
REPLAY_TOLERANCE = 1e-9

# 96 spheres of two sizes (types 1 and 2) in a 4 x 4 x 8 mm box, partly above the free surface at
# z = 5 mm, falling at 1 cm/s; the atoms are created only in a fresh run, never after read_restart.
ATOMS = """units           si
atom_style      sphere
atom_modify     map array
boundary        p p f
region          box block 0 0.004 0 0.004 0 0.008
create_box      2 box
lattice         sc 0.001
region          cloud block 0 0.004 0 0.004 0.0005 0.0058 units box
create_atoms    1 region cloud
displace_atoms  all random 1e-4 1e-4 1e-4 4321 units box
set             group all type/fraction 2 0.5 777
set             type 1 diameter 5e-4 density 2500
set             type 2 diameter 3e-4 density 2650
velocity        all set 0.002 -0.001 -0.01 units box
"""

# Every scene: gravity and a fluid with a free surface; the style under test comes on top.
COMMON = """comm_modify     vel yes cutoff 0.0012
fix             grav all gravity 9.81 vector 0 0 -1
fix             water all fluid density 1000 viscosity 1e-3 surface z 0.005
"""

CONTACTS = """pair_style      granular
pair_coeff      * * hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.5 damping tsuji
fix             floor all wall/gran granular hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.5 damping tsuji zplane 0 NULL
"""


@dataclass
class Scene:
    """A deck exercising one style: its commands (re-issued after a restart), the integrator, the
    outputs to pin (LAMMPS expressions) and the step."""

    name: str
    styles: str
    outputs: dict[str, str]
    integrator: str = "fix step all nve/sphere/fluid floor z 0"
    dt: float = 1e-4
    steps: int = 200
    layers: bool = False    # the scene writes a layer file (fix layers/hdf5)
    notes: list[str] = field(default_factory=list)

    def deck(self, phase: str, restart: Path, state: Path, layers: Path) -> str:
        """The deck of a phase: 'whole' (N at dt, then N at dt/2), 'first' (N at dt, write_restart),
        'second' (read_restart, then N at dt/2)."""
        lines = [f"read_restart {restart}" if phase == "second" else ATOMS, COMMON, self.styles, self.integrator,
                 "thermo 0"]
        lines = [line.replace("${layers}", str(layers)) for line in lines]
        half = [f"timestep {self.dt / 2!r}", f"run {self.steps}"]
        if phase in ("whole", "first"):
            lines += [f"timestep {self.dt!r}", f"run {self.steps}"]
        if phase == "first":
            lines.append(f"write_restart {restart}")
        else:
            lines += half
            lines += [f'print "RESULT {name} $({expr}:%.17g)"' for name, expr in self.outputs.items()]
            lines.append(f"write_dump all custom {state} id x y z vx vy vz omegax omegay omegaz "
                         "modify sort id format float %.17g")
        return "\n".join(lines) + "\n"


SCENES = [
    Scene("fluid_buoyancy", "fix buoy all fluid/buoyancy water\n",
          {"fx": "f_buoy[1]", "fy": "f_buoy[2]", "fz": "f_buoy[3]", "immersed": "f_buoy[4]"}),
    Scene("fluid_drag_explicit", "fix buoy all fluid/buoyancy water\n"
          "fix drag all fluid/drag water law schiller-naumann rotation yes\n",
          {"fx": "f_drag[1]", "fy": "f_drag[2]", "fz": "f_drag[3]", "unstable": "f_drag[4]", "outside": "f_drag[5]"},
          integrator="fix step all nve/sphere", dt=2e-5),
    Scene("nve_sphere_fluid", "fix buoy all fluid/buoyancy water\n"
          "fix drag all fluid/drag water law dallavalle rotation yes\n",
          {"outside": "f_step[3]", "stuck": "f_step[1]"},
          integrator="fix step all nve/sphere/fluid floor z 0.0003"),    # spheres stop above the box floor
    Scene("bingham", "unfix water\nfix water all fluid density 1200 bingham 0.3 0.02 surface z 0.005\n"
          "fix buoy all fluid/buoyancy water\nfix drag all fluid/drag water law zhang-li\n",
          {"stuck": "f_step[1]", "at_jump": "f_step[2]", "outside": "f_step[3]"}),
    Scene("concentration_grid", "fix buoy all fluid/buoyancy water\n"
          "compute conc all concentration/grid layers z 16 bounds 0 0.008 classes 4e-4 smooth 5e-4\n"
          "fix drag all fluid/drag water law difelice concentration c_conc\n"
          "thermo_style custom step c_conc[4][2] c_conc[8][2] c_conc[8][3]\n",    # keeps the grid current
          {"phi_layer4": "c_conc[4][2]", "phi_layer8": "c_conc[8][2]", "small_layer8": "c_conc[8][3]",
           "capped": "f_step[4]"}),
    Scene("lubricate_fluid", CONTACTS + "pair_style hybrid/overlay granular lubricate/fluid water inner 0.01 outer 0.5\n"
          "pair_coeff * * granular hertz/material 1e6 0.3 0.3 tangential mindlin NULL 1.0 0.5 damping tsuji\n"
          "pair_coeff * * lubricate/fluid\n"
          "fix buoy all fluid/buoyancy water\nfix drag all fluid/drag water law stokes\n",
          {"pe": "pe", "outside": "f_step[3]"}, dt=2e-6, steps=300),
    Scene("fluid_flow", "fix buoy all fluid/buoyancy water\nfix drag all fluid/drag water law stokes\n"
          "fix flow all fluid/flow water grid 8 8 16 column 0 0.008 every 2 relax 0.1\n",
          {"fz": "f_flow[3]", "peak": "f_flow[5]"}),
    Scene("fluid_flow_drift", "fix buoy all fluid/buoyancy water\nfix drag all fluid/drag water law stokes\n"
          "fix flow all fluid/flow water grid 8 8 16 column 0 0.008 drift 0.02 relax 0.1\n",
          {"fz": "f_flow[3]", "solves": "f_flow[7]"}),
    Scene("layers_hdf5", CONTACTS + "compute conc all concentration/grid layers z 16 bounds 0 0.008\n"
          "fix buoy all fluid/buoyancy water\nfix drag all fluid/drag water law stokes\n"
          "fix layers all layers/hdf5 50 ${layers} c_conc fluid water particle_density 2500\n",
          {"outside": "f_step[3]"}, dt=2e-6, steps=300, layers=True),
]


def _run(scene: Scene, phases: list[str], np_ranks: int, tmp: Path, tag: str) -> tuple[np.ndarray, dict, object]:
    from sediment.sim.layers import read_layers

    restart, state, layers = tmp / f"{tag}.restart", tmp / f"{tag}.dump", tmp / f"{tag}.h5"
    results: dict = {}
    for phase in phases:
        deck = tmp / f"{tag}_{phase}.lmp"
        deck.write_text(scene.deck(phase, restart, state, layers))
        results = run_deck(deck, {}, np_ranks, cwd=tmp).results
    frames = read_layers(layers) if scene.layers else None
    return np.loadtxt(state, skiprows=9), results, frames


def _differences(state: np.ndarray, outputs: dict, reference_state: np.ndarray, reference_outputs: dict
                 ) -> dict[str, float]:
    """Largest differences relative to each quantity's scale (0 where both are 0)."""
    if state.shape != reference_state.shape or not np.array_equal(state[:, 0], reference_state[:, 0]):
        raise AssertionError(f"different atoms: {state.shape} vs {reference_state.shape}")

    def relative(a, b):
        scale = np.max(np.abs(b))
        return float(np.max(np.abs(a - b)) / scale) if scale > 0 else float(np.max(np.abs(a)))
    diffs = {name: relative(state[:, cols], reference_state[:, cols])
             for name, cols in (("position", slice(1, 4)), ("velocity", slice(4, 7)), ("spin", slice(7, 10)))}
    if set(outputs) != set(reference_outputs):
        raise AssertionError(f"outputs {sorted(outputs)} vs pinned {sorted(reference_outputs)}")
    for name, value in outputs.items():
        ref = reference_outputs[name]
        diffs[name] = abs(value - ref) / abs(ref) if ref != 0 else abs(value)
    return diffs


def check_scene(scene: Scene, np_ranks: int, regenerate: bool = False) -> None:
    """Regression against the pinned reference, and the restart / time-step-change replay."""
    pinned = REFERENCES / f"style_{scene.name}.json"
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        state, outputs, frames = _run(scene, ["whole"], np_ranks, tmp, "whole")
        split_state, split_outputs, split_frames = _run(scene, ["first", "second"], np_ranks, tmp, "split")
    if frames is not None:
        outputs["layers_total"] = float(np.sum(frames.total[-1]))
        outputs["frames"] = float(len(frames.step))
        split_outputs["layers_total"] = float(np.sum(split_frames.total[-1]))
        split_outputs["frames"] = float(len(split_frames.step))
    if regenerate:
        REFERENCES.mkdir(parents=True, exist_ok=True)
        rows = ",\n".join(json.dumps(row) for row in state.tolist())
        pinned.write_text(f'{{"scene": "{scene.name}",\n"outputs": {json.dumps(outputs)},\n"state": [\n{rows}\n]}}\n')
        report(f"{scene.name}: pinned {pinned}")
    if not pinned.is_file():
        raise FileNotFoundError(f"{pinned}: no pinned reference; create it with "
                                f"`checks.py style_{scene.name} --regenerate`")
    reference = json.loads(pinned.read_text())
    regression = _differences(state, outputs, np.array(reference["state"]), reference["outputs"])
    replay = _differences(split_state, split_outputs, state, outputs)
    worst = max(regression, key=regression.get)
    report(f"{scene.name}: {len(state)} spheres, {2 * scene.steps} steps; vs pinned reference worst {worst} "
           f"{regression[worst]:.1e}; restart + dt change replay worst {max(replay.values()):.1e}")
    bad = {k: v for k, v in regression.items() if not v <= REGRESSION_TOLERANCE}
    assert not bad, f"{scene.name}: differs from {pinned.name}: {bad}"
    bad = {k: v for k, v in replay.items() if not v <= REPLAY_TOLERANCE}
    assert not bad, f"{scene.name}: the split run differs: {bad}"
