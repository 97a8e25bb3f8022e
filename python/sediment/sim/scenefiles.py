# SPDX-License-Identifier: GPL-2.0-or-later
"""A planned scene written out (docs/sedimentation-tests.md section 1): the LAMMPS data file, the
deck's text (the stages of its time step, the fluid and its temperature record, contacts, the layer
file), the PSD tables, and the scene described for the console."""
from __future__ import annotations

import os
from datetime import datetime, timezone
from pathlib import Path

import numpy as np

from ..lab.psd import PSD
from ..lab.readout import Suspension
from ..results import write_text
from .provenance import RUN_OUTPUTS, inputs_id
from .scene import (FLOW_COURANT, LOAD_CONCENTRATION, OVERLAP_TOLERANCE, POISSON_RATIO, RESTART_SPACING, SORT_EVERY,
                    Scene)


SAMPLE_FILES = ("sample.data", "in.sedimentation", "input_psd.csv", "simulated_psd.csv", "classes.csv")
# A two-way column of parcels: how its displaced stratification pushes back, the deck's default
# (`-var stratification grains|parcels`; fix fluid/flow, docs/effects.md section 3)
STRATIFICATION = "parcels"


def write(scene: Scene, out: Path, layer_file: str = "layers.h5", force: bool = False) -> list[Path]:
    """Writes the scene: data file, deck and PSD tables, together (under the folder's lock, staged and
    then moved into place).

    Parameters
    ----------
    scene : Scene
        From `plan`.
    out : Path
        Output folder (created).
    layer_file : str
        Name of the layer file the deck writes.
    force : bool
        Delete the files of a run in `out` whose inputs this scene changes (its layer file, restart
        files, logs), instead of refusing.

    Returns
    -------
    list of Path
        The files written.
    """
    import shutil

    from ..folders import folder_lock

    if out.exists() and not out.is_dir():
        raise ValueError(f"{out} exists and is not a folder")
    with folder_lock(out, "sample"):
        stage = out / f".sample.{os.getpid()}"
        shutil.rmtree(stage, ignore_errors=True)
        stage.mkdir()
        try:
            _write_files(scene, [stage / n for n in SAMPLE_FILES], layer_file)
            for name in runs_replaced(out, stage / "in.sedimentation", layer_file, force):
                (out / name).unlink()
            for name in SAMPLE_FILES:
                os.replace(stage / name, out / name)
        finally:
            shutil.rmtree(stage, ignore_errors=True)
    return [out / n for n in SAMPLE_FILES]


def runs_replaced(out: Path, deck: Path, layer_file: str = "layers.h5", force: bool = False) -> list[str]:
    """The files of a run in `out` (layer file, restart files, logs) that a new `deck` of another scene
    makes stale, to delete with `force`; ValueError naming them without it. A run read the deck and
    data file in place: new ones would leave its frames beside the tables of another test."""
    results = [p.name for p in (out / layer_file, out / (layer_file + ".partial"), *(out / n for n in RUN_OUTPUTS))
               if p.exists()]
    here = out / "in.sedimentation"
    if not results or (here.is_file() and inputs_id(here) == inputs_id(deck)):
        return []
    if not force:
        raise ValueError(f"{out} holds a run of another scene ({', '.join(results)}): its frames would stand beside "
                         "tables of this one; sample into another --out, or give --force to delete that run's files")
    return results


def _write_files(scene: Scene, paths: list[Path], layer_file: str) -> None:
    """sample.data, in.sedimentation, input_psd.csv, simulated_psd.csv and classes.csv, at `paths`."""
    write_data(scene, paths[0])
    write_text(paths[1], _deck(scene, paths[0].name, layer_file))
    _write_psd(scene.psd, paths[2])
    _write_psd(scene.simulated_psd(), paths[3])
    c = scene.classes
    write_text(paths[4], "diameter_um,input_mass_fraction,simulated_mass_fraction,particles,weight\n" + "".join(
        f"{d * 1e6:.6g},{m:.6g},{s:.6g},{n},{w:.6g}\n"
        for d, m, s, n, w in zip(c.diameter, c.mass_fraction, c.simulated_mass_fraction(), c.count, c.weight)))


def _write_psd(psd: PSD, path: Path) -> None:
    """The table as read_psd reads it: 12 digits, or 17 where 12 would merge two diameters."""
    diameter = psd.diameter * 1e6
    digits = 12 if len(np.unique([f"{d:.12g}" for d in diameter])) == len(diameter) else 17
    write_text(path, "diameter_um,percent_finer\n" + "".join(
        f"{d:.{digits}g},{p:.12g}\n" for d, p in zip(diameter, psd.percent_finer)))


def write_data(scene: Scene, path: Path) -> None:
    """The scene's LAMMPS data file: one atom type, diameters, density, positions and the Weights section."""
    lo, hi = scene_box(scene)
    n = len(scene.diameter)
    lines = [f"SEDIMENT sedimentation test: {n} grains ({scene.geometry})", "",
             f"{n} atoms", "1 atom types", ""]
    lines += [f"{lo[k]:.17g} {hi[k]:.17g} {a}lo {a}hi" for k, a in enumerate("xyz")]
    lines += ["", "Atoms # sphere", ""]
    rho = scene.suspension.particle_density
    lines += [f"{i + 1} 1 {d:.17g} {rho:.17g} {x:.17g} {y:.17g} {z:.17g}"
              for i, (d, (x, y, z)) in enumerate(zip(scene.diameter, scene.position))]
    lines += ["", "Weights", ""]
    lines += [f"{i + 1} {w:.17g}" for i, w in enumerate(scene.weight)]
    write_text(path, "\n".join(lines) + "\n")


def scene_box(scene: Scene) -> tuple[list[float], list[float]]:
    """The simulation box (lo, hi per axis) of the scene."""
    if scene.geometry == "slab":
        return [0.0, 0.0, -0.5 * scene.thickness], [scene.width, scene.height, 0.5 * scene.thickness]
    return [0.0, 0.0, 0.0], [scene.width, scene.width, scene.height]


def _deck(scene: Scene, data: str, layer_file: str) -> str:
    e, f = scene.effects, scene.suspension
    slab = scene.geometry == "slab"
    up = "y" if slab else "z"
    gravity = "0 -1 0" if slab else "0 0 -1"
    d_max = float(scene.diameter.max())
    stages = scene.stages()
    frames_every = scene.frame_steps()
    segments = _segments(scene, stages, frames_every)
    total_steps = sum(n for _, n in stages)
    c = scene.classes
    when = datetime.now(timezone.utc).strftime("%Y-%m-%d")
    lines = [
        f"# Sedimentation test written by `sediment sample` ({when}): {scene.psd.name or 'PSD'}",
        f"# {scene.geometry} {scene.width:.4g} x {scene.thickness:.4g} x {scene.height:.4g} m of a cylinder of "
        f"{scene.cylinder.area * 1e4:.4g} cm2 x {scene.cylinder.height:.4g} m (fraction {scene.volume_fraction:.3g}),",
        f"# {len(scene.diameter)} atoms in {int(np.sum(c.count > 0))} size classes standing for {c.represented_grains():.4g} grains "
        f"({scene.mass * 1e3:.4g} g sample, c0 = {scene.initial_concentration:.4g} kg/m3).",
        f"# Water at {f.temperature_text() if not scene.water_record else _record_text(scene.water_record)}; "
        f"effects: drag ({e.describe()}), buoyancy"
        f"{', contacts' if e.contacts or e.lubrication else ', deposit on the floor (no contacts)'}"
        f"{', lubrication' if e.lubrication else ''}.",
        f"# {len(stages)} stages, {total_steps} steps to {scene.t_end:g} s; layer frames every {frames_every} steps.",
        "#",
        "#   sediment run in.sedimentation        (or: lmp_sediment -in in.sedimentation)",
        "#   sediment run --resume in.sedimentation   continues a killed run from its last restart file",
        f"variable        layers_file index {layer_file}",
        "variable        overwrite index no    # yes: replace a layer file of another run (sediment run --force)",
        f"variable        t_end equal {scene.t_end:.12g}",
        "variable        dt_scale index 1    # multiplies every stage's time step (sediment sweep ... --parameter dt_scale)",
        "variable        field_every index 1    # steps between refreshes of the concentration field the hindered drag reads",
        "variable        resume index no     # yes: start from ${restart_file} (sediment run --resume)",
        "variable        restart_file index restart.a.bin",
        "variable        timing index no     # yes: LAMMPS's timing breakdown after each stage (where the time goes)",
    ]
    parcels = e.flow and scene.parcels
    if e.flow:
        lines += ["variable        flow index yes      # no: the one-way twin of this scene (the same grains and "
                  "schedule, whose steps the flow may shorten; the fluid at rest)",
                  'if "${flow} != yes && ${flow} != no" then &',
                  '  "print \'ERROR: variable flow must be yes or no, not ${flow}\'" "quit 2"']
    if parcels:
        lines += [f"variable        stratification index {STRATIFICATION}    # grains: the displaced stratification "
                  "pushes back with its real grains' force, not the parcels' (fix fluid/flow)",
                  'if "${stratification} != parcels && ${stratification} != grains" then &',
                  '  "print \'ERROR: variable stratification must be parcels or grains, not ${stratification}\'" "quit 2"']
    lines += [
        "",
    ]
    if not e.interacting:    # set before the box (and before read_restart), so in both branches below
        lines.append("newton          off    # no pair forces: no forces on ghosts to send back each step")
    lines += [
        "# The weights (real grains each atom stands for) come from the data file, or back from the restart file.",
        'if "${resume} == yes" then "read_restart ${restart_file}" "fix weights all property/atom d_weight" else &',
        '  "units si" "dimension ' + str(scene.dimension) + '" "atom_style sphere" "boundary ' + ('p f p' if slab else 'p p f')
        + '" "processors ' + ('* 1 1' if slab else '* * 1') + '" "fix weights all property/atom d_weight" &',
        f'  "read_data {data} fix weights NULL Weights"',
        f"# ranks side by side ({'* 1 1' if slab else '* * 1'}): each keeps its share of the grains as they settle",
        f"neighbor        {d_max:.6g} bin",
        f"atom_modify     sort {SORT_EVERY} {scene.height / scene.layers:.6g}    # neighbours in memory, layer by layer",
    ]
    if e.interacting:    # pair forces need ghosts within a contact or film reach and the skin, as LAMMPS finds them
        lines.append("comm_modify     vel yes")
    else:                # no pair forces, no ghosts needed: a cutoff far below any grain copies none
        # (each ghost is sent to the next rank every step) and keeps LAMMPS from warning of a zero one
        lines.append(f"comm_modify     cutoff {1e-9 * min(scene.width, scene.thickness):.6g}")
    lines += [
        "",
        f"fix             grav all gravity {f.gravity:.12g} vector {gravity}",
        _fluid_line(segments[0][2] or f),    # the record's first water, if any: the layer file keeps it
        f"compute         conc all concentration/grid layers {up} {scene.layers} bounds 0 {scene.height:.12g}"
        f"{f' thickness {scene.thickness:.12g}' if slab else ''} weight d_weight every ${{field_every}}"
        + (" classes " + " ".join(f"{d:.12g}" for d in scene.tag_classes) if scene.tag_classes else ""),
        "fix             buoy all fluid/buoyancy water"
        + (f" mixture c_conc {f.particle_density:.12g}" if e.buoyancy == "mixture" else ""),
    ]
    lines.append(f"fix             drag all fluid/drag water {e.fix_arguments()}")
    if e.flow:
        across, tall = scene.flow_grid()
        weights = " weight d_weight stratification ${stratification}" if parcels else ""
        lines += [f"# the flow the grains drive (two-way coupling): {across} x {across} x {tall} cells over the column, "
                  "closed by free slip at the floor and the surface; a step that would carry a grain more than",
                  f"# {FLOW_COURANT:g} cells is shortened (cfl), as the schedule's steps are sized at the start",
                  f'if "${{flow}} == yes" then "fix             flow all fluid/flow water grid {across} {across} {tall} '
                  f'column 0 {scene.height:.12g}{weights} cfl {FLOW_COURANT:g}"']
    # the swirls lift fine grains to the surface, which holds them while the flow presses them up
    surface = f" surface {up} {scene.height:.12g}" if e.flow else ""
    if e.interacting:
        lines += pair_lines(scene)
        lines += [f"fix             floor all wall/gran granular {contact_model(scene)} {up}plane 0 NULL",
                  f"fix             step all nve/sphere/fluid{surface}",
                  "# Soft contacts, made for overlaps up to "
                  f"{OVERLAP_TOLERANCE:.0%} of a diameter: the largest is reported, and twice that stops the run.",
                  "compute         overlap all contact/overlap",
                  "variable        overlap equal c_overlap",
                  f"fix             overlap_guard all halt 100 v_overlap > {2 * OVERLAP_TOLERANCE:g} error hard message yes"]
    else:
        lines.append(f"fix             step all nve/sphere/fluid floor {up} 0.0{surface}")
    lines += [
        "# a frame every frame_every steps, and each stage a whole number of them at any dt_scale: the last",
        "# frame is then the run's last step, at t_end or up to a frame past it",
        f"variable        frame_every equal $(round({frames_every}/v_dt_scale)+(round({frames_every}/v_dt_scale)<1))",
        f"fix             layers all layers/hdf5 ${{frame_every}} "
        f"${{layers_file}} c_conc fluid water particle_density {f.particle_density:.12g} overwrite ${{overwrite}} &",
        "                end_time ${t_end}    # complete only when the frames reach the end of the test",
        "",
        "thermo_style    custom step time dt f_layers" + (" c_overlap" if e.interacting else ""),
        f"thermo          {frames_every * 5}",
        "thermo_modify   norm no flush yes    # each row at once: the progress bar follows them",
        f'print           "SEDIMENT plan steps $(ceil({total_steps}/v_dt_scale)) t_end {scene.t_end:.12g}"',
        "# Two restart files in turn (one is always complete); each stage runs up to its last step, so a",
        "# resumed run skips the stages it has done and finishes the one it was in. One every twentieth of",
        f"# the run, and {RESTART_SPACING} steps apart at least: rank 0 writes each one, in several steps' time.",
        f"# At multiples of the atoms' sort ({SORT_EVERY} steps), so that a resumed run sums in the order of one",
        "# never stopped (a two-way column's flow grows round-off into another trajectory).",
        # max(a, b) written out: LAMMPS formulas have no two-argument max (its max() reduces a compute).
        f"variable        restart_every equal {SORT_EVERY}*ceil(ceil({total_steps}/20/v_dt_scale)/{SORT_EVERY})",
        f"restart         $(v_restart_every+(v_restart_every<{RESTART_SPACING})*({RESTART_SPACING}-v_restart_every)) "
        "restart.a.bin restart.b.bin",
        "variable        stage_end equal 0",
    ]
    for dt, steps, water, first in segments:
        # the time step set once per stage: LAMMPS adds up the time at each change, and the parts of a
        # stage then end on the same times as the whole stage would
        commands = ([f'"{_fluid_line(water)}"'] if water is not None else []) \
            + ([f'"timestep $({dt:.17g}*v_dt_scale)"'] if first else []) + ['"run ${stage_end} upto post ${timing}"']
        lines += [f"variable        stage_end equal $(v_stage_end+ceil(ceil({steps}/v_dt_scale)/v_frame_every)*v_frame_every)",
                  f'if "$(step) < ${{stage_end}}" then {" ".join(commands)}']
    if e.flow:
        lines += ["# Steps the flow shortened leave the stages short of t_end: the run goes on at the last stage's step",
                  "# (shortened where the flow asks) and stops at the first frame at or past t_end",
                  "variable        reached equal time>=${t_end}*(1-1e-9)",
                  'if "$(v_reached) == 0" then &',
                  '  "fix             finish all halt ${frame_every} v_reached != 0 error continue message no" &',
                  '  "run             1000000000 post ${timing}" &',
                  '  \'print "SEDIMENT end step $(step) t $(time:%.12g)"\'    # a halted run prints no last thermo row']
    return "\n".join(lines) + "\n"


DRIFT_STEP = 0.05    # C: the water's record is followed in steps of this


def _record_text(record: tuple[tuple[float, float], ...]) -> str:
    temperatures = [t for _, t in record]
    return (f"{min(temperatures):g}-{max(temperatures):g} C as its record over {record[-1][0] / 3600:.3g} h goes (the fluid "
            f"re-issued as it moves by {DRIFT_STEP:g} C)")


def _fluid_line(water: Suspension) -> str:
    return f"fix             water all fluid density {water.fluid_density:.12g} viscosity {water.viscosity:.12g}"


def _segments(scene: Scene, stages: list[tuple[float, int]],
              every: int) -> list[tuple[float, int, Suspension | None, bool]]:
    """The deck's runs (time step, steps, water, whether a stage begins): each stage whole, or, with a
    water record, split at the frames where the record has moved by more than DRIFT_STEP since the last
    change, each part with the water at its middle."""
    if not scene.water_record:
        return [(dt, steps, None, True) for dt, steps in stages]
    times, temperatures = (np.array(v, float) for v in zip(*scene.water_record))

    def water_at(t: float) -> Suspension:
        return Suspension.at_temperature(float(np.interp(t, times, temperatures)), scene.suspension.particle_density,
                                         scene.suspension.gravity)

    out, start = [], 0.0
    for dt, steps in stages:
        frames = np.arange(0, steps, every)
        middle = start + (frames + 0.5 * every) * dt
        level = np.interp(middle, times, temperatures)
        begin = 0    # the frame the current part starts at
        for k in range(1, len(frames) + 1):
            if k == len(frames) or abs(level[k] - level[begin]) > DRIFT_STEP:
                end = steps if k == len(frames) else frames[k]
                out.append((dt, int(end - frames[begin]), water_at(start + 0.5 * (frames[begin] + end) * dt), begin == 0))
                begin = k
        start += steps * dt
    return out


def contact_model(scene: Scene) -> str:
    """The grains' contact model as pair_coeff granular takes it: Hertz at the scene's soft modulus."""
    return (f"hertz/material {scene.contact_modulus():.6g} 0.3 {POISSON_RATIO:g} tangential mindlin NULL 1.0 0.5 "
            "damping tsuji")


def pair_lines(scene: Scene) -> list[str]:
    """The deck's pair_style and pair_coeff lines: the contacts, with the squeeze films overlaid."""
    if scene.effects.lubrication:
        return ["pair_style      hybrid/overlay granular lubricate/fluid water inner 0.01 outer 0.5 limit yes",
                f"pair_coeff      * * granular {contact_model(scene)}", "pair_coeff      * * lubricate/fluid"]
    return ["pair_style      granular", f"pair_coeff      * * {contact_model(scene)}"]


def describe(scene: Scene) -> str:
    """A short report: particles, classes, and the PSD actually simulated against the input."""
    c = scene.classes
    stages = scene.stages()
    sim = scene.simulated_psd()
    worst = float(np.max(np.abs(sim.percent_finer - scene.psd.at(c.edges))))
    lines = [f"{len(scene.diameter)} particles in {int(np.sum(c.count > 0))} size classes "
             f"({c.diameter[0] * 1e6:.3g}-{c.diameter[-1] * 1e6:.3g} um), standing for {c.represented_grains():.4g} real grains "
             f"({'weights ' + f'{c.weight.min():.3g}-{c.weight.max():.3g}' if not np.all(c.weight == 1) else 'real grains'})",
             f"sub-volume: {scene.geometry} {scene.width * 1e3:.4g} x {scene.thickness * 1e3:.4g} x "
             f"{scene.height * 1e3:.4g} mm = {scene.volume_fraction:.3g} of the cylinder; "
             f"c0 = {scene.initial_concentration:.4g} kg/m3",
             f"simulated PSD vs input at the class edges: max difference {worst:.2f} percentage points",
             f"time: {len(stages)} stages, {sum(n for _, n in stages)} steps to {scene.t_end:g} s "
             f"(dt {stages[0][0]:.3g} .. {stages[-1][0]:.3g} s)"]
    if scene.effects.flow:
        across, tall = scene.flow_grid()
        lines.append(f"two-way: fix fluid/flow on {across} x {across} x {tall} cells of "
                     f"{scene.width / across * 1e3:.3g} mm; "
                     f"the start's flow, {scene.flow_speed() * 1e3:.3g} mm/s rms, sets the first step "
                     f"({scene.flow_time_step():.3g} s); `-var flow no` runs the one-way twin"
                     + ("" if not scene.parcels else
                        "; `-var stratification grains|parcels`: the displaced stratification pushes back with "
                        f"its real grains' force or the parcels' own (default {STRATIFICATION})"))
    first, last = scene.psd.percent_finer[0], scene.psd.percent_finer[-1]
    if first > 0 or last < 100:
        lines.append(f"note: the PSD table runs from {first:g} to {last:g} % finer; the {first + 100 - last:g} % of the "
                     "mass outside its diameters is not simulated, and the simulated PSD is renormalised to 100 %")
    if scene.effects.interacting:
        lines.append(f"contacts: E = {scene.contact_modulus():.3g} Pa, the softest keeping overlaps within "
                     f"{OVERLAP_TOLERANCE:.0%} (fastest grain's impact, {LOAD_CONCENTRATION:g}x the deposit's weight "
                     f"per grain); largest overlap in the thermo output, the run stops at {2 * OVERLAP_TOLERANCE:.0%}")
        lines.append(f"contacts: dt = {stages[0][0]:.3g} s (Rayleigh time / 5 of the smallest grain): "
                     f"{stages[0][1]:.3g} steps x {len(scene.diameter)} particles")
    return "\n".join(lines)
