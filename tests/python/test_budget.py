# SPDX-License-Identifier: GPL-2.0-or-later
"""The test's physics as options (drag law, hindrance, water temperature) and the error budget: what
each modelling choice moves, and the band a readout puts around its readings (docs/error-budget.md)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sediment import cli
from sediment.lab.psd import read_psd
from sediment.lab.readout import Suspension
from sediment.sim.scene import Effects
from sediment.studies.budget import CHOICES, band_of, error_budget

PSDS = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd"


def test_the_deck_names_the_drag_the_hindrance_and_the_water(tmp_path):
    out = tmp_path / "warm"
    assert cli.main(["sample", str(PSDS / "sample5.csv"), "--particles", "500", "--temperature", "25",
                     "--hindrance", "garside", "--out", str(out)]) == 0
    deck = (out / "in.sedimentation").read_text()
    water = Suspension.at_temperature(25.0)
    assert f"density {water.fluid_density:.12g} viscosity {water.viscosity:.12g}" in deck
    assert "fluid/drag water law standard hindrance garside concentration c_conc" in deck
    assert "# Water at 25 C" in deck
    bravo = tmp_path / "bravo"
    assert cli.main(["sample", str(PSDS / "sample5.csv"), "--particles", "500", "--drag", "difelice",
                     "--out", str(bravo)]) == 0
    assert "fluid/drag water law difelice concentration c_conc" in (bravo / "in.sedimentation").read_text()
    clear = tmp_path / "clear"
    assert cli.main(["sample", str(PSDS / "sample5.csv"), "--particles", "500", "--hindrance", "none",
                     "--out", str(clear)]) == 0
    deck = (clear / "in.sedimentation").read_text()
    assert "fluid/drag water law standard\n" in deck and "concentration c_conc" not in deck.split("fluid/drag")[1]


@pytest.mark.parametrize("args, message", [
    (["--drag", "difelice", "--hindrance", "garside"], "--drag difelice is Dallavalle's curve with Di Felice's"),
    (["--drag", "schiller-naumann", "--hindrance", "richardson-zaki"], "does not take hindrance richardson-zaki"),
    (["--temperature", "45"], "within 0-40 C"),
    (["--drag", "standart"], "invalid choice: 'standart'"),
])
def test_physics_that_does_not_go_is_refused(tmp_path, capsys, args, message):
    try:
        code = cli.main(["sample", str(PSDS / "sample5.csv"), "--out", str(tmp_path / "o"), *args])
    except SystemExit as exit_:    # argparse refuses a value of a choice or type
        code = exit_.code
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_effects_keep_bravo_et_al_whole():
    assert Effects("difelice").hindrance == "difelice"
    assert Effects().describe() == "standard, hindered (richardson-zaki)"
    with pytest.raises(ValueError, match="buoyancy must be plain or mixture"):
        Effects(buoyancy="heavy")


def test_budget_rows_follow_the_physics(tmp_path):
    """A short test (30 min, 100 layers): the drag curve and the hindrance exponent move the readings, a
    choice that changes nothing moves nothing, and the readout takes the physical total as its band."""
    psd = read_psd(PSDS / "sample5.csv")
    keep = [c for c in CHOICES if c.key in ("curve", "exponent", "warmer", "courant", "dallavalle")]
    budget = error_budget(psd, tmp_path / "runs", particles=1500, courant=2.0, replicas=2, jobs=2, progress=False,
                          choices=keep, name="sample5", t_end=1800.0, layers=100, classes=20)
    rows = {k: change for k, _, _, change in budget.rows}
    assert set(rows) == {"curve", "exponent", "warmer", "courant", "dallavalle", "parcels", "wall", "brownian"}
    for key in ("curve", "exponent", "warmer", "dallavalle"):
        assert max(rows[key].values()) > 0.02, key       # each a real change of the physics
    # 1 % more drag moves the readings less than 1 C (2.5 % in viscosity)
    assert max(rows["curve"].values()) < max(rows["warmer"].values())
    assert 0 < rows["wall"]["pipette"] < 0.2 and 0 < rows["brownian"]["pipette"] < 0.1
    total = budget.physical_total()
    physical = ("curve", "exponent", "warmer", "wall", "brownian")
    assert total == pytest.approx({n: np.sqrt(sum(rows[k][n] ** 2 for k in physical)) for n in total})
    from sediment.studies.budget import save
    save([budget], tmp_path)
    assert band_of(tmp_path / "budget.json") == pytest.approx(total)
    (tmp_path / "empty.json").write_text("[]")
    with pytest.raises(ValueError, match="not a budget.json"):
        band_of(tmp_path / "empty.json")
    with pytest.raises(ValueError, match="no sample 'sample9'"):
        band_of(tmp_path / "budget.json", "sample9")
    # the readout's band: each reading's low and high ends
    run = tmp_path / "runs" / "reference"
    assert cli.main(["readout", str(run / "layers.h5"), "--band", str(tmp_path / "budget.json"),
                     "--out", str(tmp_path / "readout")]) == 0
    rows = np.genfromtxt(tmp_path / "readout" / "pipette.csv", delimiter=",", names=True)
    assert np.allclose(rows["high"] - rows["percent_finer"], total["pipette"], atol=1e-3)
    summary = json.loads((tmp_path / "budget.json").read_text())[0]
    assert summary["sample"] == "sample5" and "physical_total_pp" in summary


def test_mixture_buoyancy_leaves_the_deposit_on_the_floor(tmp_path):
    """Parcels stop on the floor without contacts, where the grid's fraction exceeds any packing: the
    mixture buoyancy caps it (fix fluid/buoyancy max_fraction), so the deposit stays down and no reading
    rises with time (uncapped, sample 1's hydrometer read 2.35 % finer after 24 h where the plain-buoyancy
    run reads 0, and in the error budget's run 25.6 % at 250 min after 24.2 % at 60 min)."""
    from sediment.lab.granulometry import read_all
    from sediment.lab.readout import Column
    from sediment.sim.layers import read_layers
    from sediment.sim.run import run_batch
    from sediment.sim.scene import plan
    from sediment.sim.scenefiles import write

    scene = plan(read_psd(PSDS / "sample1.csv"), particles=20000, courant=2.0, effects=Effects(buoyancy="mixture"))
    write(scene, tmp_path)
    assert "fluid/buoyancy water mixture c_conc 2650" in (tmp_path / "in.sedimentation").read_text()
    run_batch(tmp_path / "in.sedimentation")
    readings, _ = read_all(Column.from_layers(read_layers(tmp_path / "layers.h5")), ["hydrometer", "pipette"])
    for r in readings:
        assert np.all(np.diff(r.percent_finer) <= 1e-9), r.instrument
        assert r.percent_finer[-1] < 0.5, r.instrument    # after 24 h the finest grains are near the floor


def test_terminal_takes_the_water_temperature_and_a_hindrance(capsys):
    assert cli.main(["terminal", "--law", "stokes", "--diameter", "10e-6", "--particle-density", "2650",
                     "--temperature", "30", "--hindrance", "garside", "--solid-fraction", "0.2"]) == 0
    out = capsys.readouterr().out
    water = Suspension.at_temperature(30.0)
    stokes = (2650 - water.fluid_density) * 9.81 * 1e-10 / (18 * water.viscosity)
    speed = float(out.split("terminal velocity: ")[1].split()[0])
    assert speed == pytest.approx(stokes, rel=1e-6)
    assert "(exponent 5.1)" in out    # Garside & Al-Dibouni's low-Re exponent
    assert cli.main(["terminal", "--diameter", "1e-5", "--particle-density", "2650", "--temperature", "20",
                     "--viscosity", "1e-3"]) == 2
    assert "--temperature sets the water's density and viscosity" in capsys.readouterr().err
    assert cli.main(["terminal", "--diameter", "1e-5", "--particle-density", "2650", "--solid-fraction", "0.1"]) == 2
    assert "--hindrance and --solid-fraction go together" in capsys.readouterr().err
