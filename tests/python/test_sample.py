# SPDX-License-Identifier: GPL-2.0-or-later
"""`sediment sample` and `sediment run`: the scene of a sedimentation test, and the end-to-end test of
issue 4 (sample -> run -> readout) on sample 5."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from sediment import _core, cli
from sediment.lab.psd import discretise, read_psd
from sediment.sim.run import run_batch
from sediment.lab.settling import terminal_speed
from sediment.sim.scene import Cylinder, Effects, meeting_modulus, plan
from sediment.sim.scenefiles import write

PSDS = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd"


def test_parcels_carry_the_mass_of_each_class_exactly():
    psd = read_psd(PSDS / "sample5.csv")
    real = discretise(psd, 40, 0.06, 2650.0, 1e-5)
    parcels = discretise(psd, 40, 0.06, 2650.0, 1e-5, particles=4000)
    # the same real grains per class, now as count x weight; the simulated PSD is the discretised one
    assert np.allclose(parcels.count * parcels.weight,
                       6 * 0.06 * parcels.mass_fraction * 1e-5 / (2650 * np.pi * parcels.diameter ** 3), rtol=1e-12)
    assert np.allclose(parcels.simulated_mass_fraction(), parcels.mass_fraction / parcels.mass_fraction.sum())
    assert abs(parcels.count.sum() - 4000) <= 40
    # real grains at this fraction: at least one per class, which distorts the coarse end
    assert real.count.min() >= 1 and np.all(real.weight == 1)


def test_placement_is_stratified_inside_the_column():
    scene = plan(read_psd(PSDS / "sample5.csv"), particles=4000, layers=100)
    z, d = scene.position[:, 2], scene.diameter
    assert np.all(z - d / 2 >= 0) and np.all(z + d / 2 <= scene.height)
    assert np.all((scene.position[:, :2] >= 0) & (scene.position[:, :2] <= scene.width))
    # every class is spread evenly: in each fifth of the height, a fifth of its parcels (+- 1 row)
    for diameter in np.unique(d)[::8]:
        heights = z[d == diameter]
        per_fifth = np.histogram(heights, bins=5, range=(0, scene.height))[0]
        assert np.all(np.abs(per_fifth - len(heights) / 5) <= 2 + 0.1 * len(heights) / 5)


def test_slab_is_the_axial_section_in_2d():
    scene = plan(read_psd(PSDS / "sample2.csv"), geometry="slab", cylinder=Cylinder.bravo(), particles=2000)
    assert scene.dimension == 2 and scene.width == pytest.approx(0.0635)
    assert scene.thickness == pytest.approx(70e-6) and np.all(scene.position[:, 2] == 0)
    assert scene.volume_fraction == pytest.approx(0.0635 * 70e-6 / (np.pi / 4 * 0.0635 ** 2))


def test_time_steps_double_after_the_largest_grains_have_left():
    scene = plan(read_psd(PSDS / "sample5.csv"), particles=2000, layers=200, t_end=86400.0, courant=1.0)
    stages = scene.stages()
    v_max = terminal_speed(scene.suspension, scene.classes.diameter.max(), "standard")    # the scene's default law
    layer = scene.height / scene.layers
    assert stages[0][0] == pytest.approx(layer / v_max)                 # one layer per step at first
    default = plan(read_psd(PSDS / "sample5.csv"), particles=2000, layers=200, t_end=86400.0)
    assert 3 * layer / v_max < default.stages()[0][0] <= 4 * layer / v_max    # default Courant 4 (at most: whole frames)
    for (dt, n), (dt_next, _) in zip(stages[1:-2], stages[2:-1]):
        assert dt_next == pytest.approx(2 * dt)
    assert stages[-1][0] <= 2 * stages[-2][0]                          # the last is cut to end on time
    times = np.cumsum([dt * n for dt, n in stages])
    assert times[-1] == pytest.approx(86400.0, rel=1e-12) and times[-2] < 86400.0
    # after time t only grains slower than H / t remain: each stage's step keeps them within a layer
    starts = np.concatenate([[0.0], times[:-1]])
    for (dt, _), t in zip(stages, starts):
        assert dt * min(v_max, scene.height / t if t > 0 else v_max) <= layer * (1 + 1e-12)
    assert sum(n for _, n in stages) < 3000


def test_a_short_test_ends_on_time():
    scene = plan(read_psd(PSDS / "sample5.csv"), particles=2000, t_end=1e-6)
    assert sum(dt * n for dt, n in scene.stages()) == pytest.approx(1e-6, rel=1e-12)


def test_the_deck_prints_where_the_time_goes_when_asked(tmp_path):
    """`-var timing yes` gives LAMMPS's timing breakdown after each stage (benchmarks/planner.py
    --scaling reads it); by default the stages stay quiet."""
    scene = plan(read_psd(PSDS / "sample5.csv"), particles=500, t_end=600.0)
    write(scene, tmp_path)
    stages = len(scene.stages())
    quiet = run_batch(tmp_path / "in.sedimentation")
    timed = run_batch(tmp_path / "in.sedimentation", {"timing": "yes", "overwrite": "yes"})
    assert len(quiet.loops) == len(timed.loops) == stages > 1
    assert quiet.text.count("Modify  |") == 0 and timed.text.count("Modify  |") == stages


def test_the_water_follows_its_temperature_record(tmp_path):
    """A record that warms the water from 20 to 35 C halfway: the frames before are those of the run in
    water at 20 C throughout, byte for byte; after it the fines fall faster (a third less viscous)."""
    from sediment.lab.readout import Suspension
    from sediment.sim.layers import read_layers

    def run(name: str, record: tuple) -> object:
        scene = plan(read_psd(PSDS / "sample5.csv"), particles=3000, t_end=3600.0, layers=100,
                     suspension=Suspension.at_temperature(20.0))
        scene.water_record = record
        write(scene, tmp_path / name)
        run_batch(tmp_path / name / "in.sedimentation")
        return read_layers(tmp_path / name / "layers.h5")

    plain = run("plain", ())
    warmed = run("warmed", ((0.0, 20.0), (1800.0, 20.0), (1800.001, 35.0), (3600.0, 35.0)))
    text = (tmp_path / "warmed" / "in.sedimentation").read_text()
    assert "Water at 20-35 C as its record" in text and "viscosity 0.0007188" in text
    before = plain.time <= 1800.0
    # the same frames at the same times (LAMMPS adds up the time at each run: within a unit of the last
    # place), and the last exactly at the end of the test, where the last readings are taken
    assert np.allclose(plain.time, warmed.time, rtol=1e-15) and warmed.time[-1] == plain.time[-1] == 3600.0
    assert 0 < before.sum() < len(plain.time)
    assert np.array_equal(plain.total[before], warmed.total[before])
    # solids left in the upper half at the end: fewer in the warmed water
    upper = plain.centres > 0.5 * plain.centres.max()
    assert warmed.total[-1, upper].sum() < 0.95 * plain.total[-1, upper].sum()
    # each frame records the water its steps ran in (the fluid re-issued at 1800 s), and a readout takes
    # each reading's grains through the water as it changed: the 2 min reading in water at 20 C, the
    # 60 min one half in each (Stokes' speed goes as (rho_p - rho_f) / mu)
    cold, warm = Suspension.at_temperature(20.0), Suspension.at_temperature(35.0)
    assert plain.fluid is not None and np.allclose(plain.fluid, [cold.fluid_density, cold.viscosity], rtol=1e-11)
    assert np.allclose(warmed.fluid[before], [cold.fluid_density, cold.viscosity], rtol=1e-11)
    assert np.allclose(warmed.fluid[~before], [warm.fluid_density, warm.viscosity], rtol=1e-11)
    from sediment.lab.readout import Column, Hydrometer
    column = Column.from_layers(warmed)
    assert "changed over the test" in column.water_text() and Column.from_layers(plain).water is None
    readings = Hydrometer.astm_152h().read(column, [120.0, 3600.0])
    (early, late), (d_early, d_late) = readings.depth, readings.diameter
    assert d_early == pytest.approx(cold.stokes_diameter(early, 120.0), rel=1e-9)
    rate = [(f.particle_density - f.fluid_density) / f.viscosity for f in (cold, warm)]
    exact = math.sqrt(18 * late / (cold.gravity * 1800.0 * sum(rate)))
    # (the water goes from cold to warm between the frame at 1800 s and the next, linear between them)
    gap = np.min(warmed.time[~before]) - 1800.0
    assert d_late == pytest.approx(exact, rel=gap / 3600.0)
    assert abs(d_late / cold.stokes_diameter(late, 3600.0) - 1) > 0.05 < abs(d_late / warm.stokes_diameter(late, 3600.0) - 1)


def test_contacts_without_a_floor_hold_the_grains_meetings():
    """In a triply periodic box grains meet only each other. Two sizes 1:3 settling in Stokes' regime
    (speeds 1:9): the modulus is the larger of the head-on impact at the difference of their speeds and
    the coarse grain riding on the fine one, both from Hertz's laws for the pair's reduced mass and
    radius (E* = E / (2 (1 - nu^2)), overlap 1 % of the fine diameter)."""
    from sediment.lab.readout import Suspension
    f = Suspension()
    d_s, v_s, nu, overlap = 20e-6, 1e-4, 0.3, 0.01
    d, v = np.array([d_s, 3 * d_s]), np.array([v_s, 9 * v_s])
    mass = f.particle_density * math.pi / 6 * d ** 3
    reduced_mass, reduced_radius = mass[0] * mass[1] / mass.sum(), (d[0] / 2) * (d[1] / 2) / (d.sum() / 2)
    delta = overlap * d_s
    youngs = 2 * (1 - nu ** 2)
    # head on: m* v^2 / 2 = (8/15) E* sqrt(R*) delta^(5/2) at the speed between them
    impact = youngs * 15 * reduced_mass * (v[1] - v[0]) ** 2 / (16 * math.sqrt(reduced_radius) * delta ** 2.5)
    # riding: the pair falls at 7 v_s (their Stokes drags carry both weights), the coarse one pressing with
    # 27 W_s (1 - 7/9) = 6 W_s, F = (4/3) E* sqrt(R*) delta^(3/2)
    weight = (f.particle_density - f.fluid_density) * f.gravity * math.pi / 6 * d_s ** 3
    riding = youngs * 3 * 6 * weight / (4 * math.sqrt(reduced_radius) * delta ** 1.5)
    assert meeting_modulus(f, d, v) == pytest.approx(max(impact, riding), rel=1e-9)
    assert meeting_modulus(f, d[::-1], v[::-1]) == meeting_modulus(f, d, v)
    # one size settling at one speed meets nothing head on and rides on nothing
    assert meeting_modulus(f, d[:1], v[:1]) == 0.0
    # grains lighter than the fluid rise, the larger pushing the smaller up: riding as hard as grains as
    # much heavier than the fluid (a plastic of 1200 kg/m3 against one of 796.4), head on by their own mass
    heavy, light = Suspension(particle_density=1200.0), Suspension(particle_density=2 * f.fluid_density - 1200.0)
    assert meeting_modulus(light, d, -v) == pytest.approx(
        max(impact * light.particle_density / f.particle_density,
            riding * (heavy.particle_density - f.fluid_density) / (f.particle_density - f.fluid_density)), rel=1e-9)


def test_contacts_need_real_grains_and_set_the_step(tmp_path):
    psd = read_psd(PSDS / "sample2.csv")
    with pytest.raises(ValueError, match="contacts and lubrication need real grains"):
        plan(psd, effects=Effects(contacts=True))
    with pytest.raises(ValueError, match="real grains in this sub-volume"):
        plan(read_psd(PSDS / "sample3.csv"), particles=None, width=1e-3)
    # a 3 mm column at the sample's concentration (60 g per 1000 mL): about 1900 real grains
    scene = plan(psd, particles=None, width=3e-4, cylinder=Cylinder(27.8e-4, 0.003), mass=0.06 * 0.003 / 0.36,
                 t_end=2e-5, effects=Effects(lubrication=True))
    dt, steps = scene.stages()[0]
    assert steps == math.ceil(2e-5 / dt) and len(scene.diameter) > 1000
    # The contacts: the softest modulus keeping a 1 % overlap both for the fastest grain's impact on the floor
    # and under three times the deposit's buoyant weight on one grain's cross-section (here the load decides),
    # and a fifth of the smallest grain's Rayleigh time.
    f, sizes = scene.suspension, scene.classes.diameter[scene.classes.count > 0]
    v_max = terminal_speed(f, sizes.max(), scene.effects.drag)
    impact = _core.hertz_modulus_for_overlap("wall", f.particle_density, v_max, 0.01, 0.3)
    pressure = scene.initial_concentration * scene.height * (1 - f.fluid_density / f.particle_density) * f.gravity
    load = _core.hertz_modulus_for_load(3 * pressure, 0.01, 0.3)
    youngs = max(impact, load)
    assert load > impact and scene.contact_modulus() == pytest.approx(youngs, rel=1e-12)
    assert _core.hertz_impact_overlap("wall", f.particle_density, v_max, scene.contact_modulus(), 0.3) < 0.01
    assert dt == pytest.approx(0.2 * _core.rayleigh_time(sizes.min() / 2, f.particle_density, youngs, 0.3), rel=1e-12)
    # no two grains overlap (periodic across, not along the height)
    p, r = scene.position, scene.diameter / 2
    delta = p[:, None, :] - p[None, :, :]
    delta[..., :2] -= scene.width * np.rint(delta[..., :2] / scene.width)
    gap = np.linalg.norm(delta, axis=2) - (r[:, None] + r[None, :])
    np.fill_diagonal(gap, 1.0)
    assert gap.min() >= 0
    # the deck with contacts, lubrication and the wall runs (a few steps, 2 ranks)
    write(scene, tmp_path)
    deck = (tmp_path / "in.sedimentation").read_text()
    assert "compute         overlap all contact/overlap" in deck and "halt 100 v_overlap > 0.02 error hard" in deck
    assert cli.main(["run", str(tmp_path / "in.sedimentation"), "--np", "2", "--quiet"]) == 0


def test_sample_rejects_what_it_cannot_build(tmp_path, capsys):
    psd = PSDS / "sample5.csv"
    assert cli.main(["sample", str(psd), "--particles", "10", "--out", str(tmp_path)]) == 2
    assert "10 particles cannot sample 40 size classes" in capsys.readouterr().err
    assert cli.main(["sample", str(psd), "--width", "0.2", "--out", str(tmp_path)]) == 2
    assert "does not fit the cylinder" in capsys.readouterr().err
    falling = tmp_path / "falling.csv"
    falling.write_text("diameter_um,percent_finer\n2,10\n5,5\n")
    assert cli.main(["sample", str(falling), "--out", str(tmp_path)]) == 2
    assert "must not decrease" in capsys.readouterr().err
    assert cli.main(["run", str(tmp_path / "missing.lmp")]) == 2
    assert "no such deck" in capsys.readouterr().err
    for text, message in [("diameter_um,percent_finer\n2,10\n", "needs the columns time_min and temperature_C"),
                          ("time_min,temperature_C\n10,20\n5,21\n", "must be >= 0 and increase"),
                          ("time_min,temperature_C\n10,55\n", "within 0-40 C"),
                          ("time_min,temperature_C\n10,\n", "no temperatures recorded")]:
        record = tmp_path / "record.csv"
        record.write_text(text)
        assert cli.main(["sample", str(psd), "--temperature-record", str(record), "--out", str(tmp_path / "r")]) == 2
        assert message in capsys.readouterr().err


def test_run_reports_the_lammps_error(tmp_path, capsys):
    deck = tmp_path / "in.bad"
    deck.write_text("units si\natom_style sphere\nregion box block 0 1 0 1 0 1\ncreate_box 1 box\n"
                    "fix f all fluid density 1000 viscosity -1\n")
    assert cli.main(["run", str(deck), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "in.bad failed" in err and "Fix fluid" in err


def test_any_time_step_scale_ends_on_a_frame_and_an_unread_variable_is_refused(tmp_path, capsys):
    """A stage is a whole number of frames at every dt_scale (`sediment sweep --dt`): sample 2's 6 cm
    minute has a frame every 5 steps, every 3 at dt_scale 2 (LAMMPS rounds 2.5 up), and ended two
    steps short of its last frame, before t_end, which fix layers/hdf5 refused. A --var the deck never
    reads would run it as if not given: refused, naming it."""
    out = tmp_path / "s"
    assert cli.main(["sample", str(PSDS / "sample2.csv"), "--height", "0.06", "--t-end", "60", "--particles", "2000",
                     "--out", str(out)]) == 0
    for scale in ("2", "3"):
        assert cli.main(["run", str(out / "in.sedimentation"), "--var", "dt_scale", scale, "--force", "--quiet"]) == 0
        assert "60.9239 s simulated" in capsys.readouterr().out    # to the stage's last frame past 60 s
    assert cli.main(["run", str(out / "in.sedimentation"), "--var", "flow", "yes", "--quiet"]) == 2
    assert "never reads a variable 'flow'" in capsys.readouterr().err


def test_end_to_end_sample5_hydrometer_follows_the_simulated_psd(tmp_path, capsys):
    """sample -> run (2 MPI ranks) -> readout on sample 5: 3000 parcels, the full 0.36 m column, to
    250 min (the D422 readings that cover 5-50 um). The hydrometer must read the simulated PSD within
    5 percentage points between 5 and 50 um (issue 4)."""
    out = tmp_path / "sample5"
    assert cli.main(["sample", str(PSDS / "sample5.csv"), "--particles", "3000", "--layers", "200",
                     "--t-end", "15000", "--out", str(out)]) == 0
    assert cli.main(["run", str(out / "in.sedimentation"), "--np", "2", "--quiet"]) == 0
    assert cli.main(["readout", str(out / "layers.h5"), "--out", str(out / "readout")]) == 0
    printed = capsys.readouterr().out
    rows = np.genfromtxt(out / "readout" / "hydrometer.csv", delimiter=",", names=True)
    simulated = read_psd(out / "simulated_psd.csv")
    d = rows["diameter_um"]
    inside = (d >= 5) & (d <= 50)
    error = np.abs(rows["percent_finer"] - simulated.at(d * 1e-6))[inside]
    print(f"hydrometer vs simulated PSD, {inside.sum()} readings in 5-50 um: max {error.max():.2f}, "
          f"mean {error.mean():.2f} points")
    assert inside.sum() >= 4 and error.max() < 5.0
    assert "mean_abs_error_points" in printed and "simulated hydrometer" in " ".join(printed.split())
    for name in ("granulometry.png", "granulometry.pdf", "errors.csv", "buoyancy.csv", "pipette.csv"):
        assert (out / "readout" / name).stat().st_size > 0


def test_a_table_not_spanning_0_to_100_percent_is_said_to_be_renormalised(tmp_path):
    table = tmp_path / "psd.csv"
    table.write_text("diameter_um,percent_finer\n5,10\n20,50\n60,90\n")
    from sediment.sim.scenefiles import describe
    text = describe(plan(read_psd(table), particles=2000))
    assert "runs from 10 to 90 % finer; the 20 % of the mass outside its diameters is not simulated" in text
