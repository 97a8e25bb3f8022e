# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment invert: sheets a laboratory keeps, refused where no sedimenting suspension reads them, and a
sheet of known answer inverted (docs/inverse.md)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from sediment import cli
from sediment.lab.inverse import LabTest, effective_times, invert, whole_sample_reading
from sediment.lab.psd import read_psd
from sediment.lab.readout import Suspension
from sediment.lab.sheet import SheetError, check_sheet, read_sheet

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "inverse"
HYDROMETER = "time_min,reading,temperature_C\n"


def _sheet(tmp_path: Path, text: str, name: str = "sheet.csv") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.mark.parametrize("text, message", [
    ("", "empty sheet"),
    ("time,R\n1,40\n", "is none of the sheets"),
    (HYDROMETER, "no readings below the header"),
    (HYDROMETER + "2,40,20\n1,45,20\n", "must be > 0 and increase"),
    (HYDROMETER + "1,45,20\n2,40,\n", "no temperature in row(s) 3"),
    (HYDROMETER + "1,1.030,20\n2,1.025,20\n", "look like specific gravities"),
    (HYDROMETER + "1,45,55\n", "outside 0-40 C"),
    (HYDROMETER + "1,abc,20\n", "reading 'abc' is not a number"),
    ("time_min,depth_cm,mass_g\n1,-10,1\n", "depths must be > 0"),
])
def test_sheets_that_cannot_be_a_test_are_refused(tmp_path, text, message):
    with pytest.raises(SheetError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_sheet(_sheet(tmp_path, text))


def test_readings_no_suspension_gives_are_refused(tmp_path):
    test, water = LabTest(), Suspension()
    rising = read_sheet(_sheet(tmp_path, HYDROMETER + "1,45,20\n2,40,20\n4,42,20\n"))
    whole = whole_sample_reading(rising, test, water)
    with pytest.raises(SheetError, match="at 4 min .* goes back towards the initial one"):
        check_sheet(rising, whole, 0.5)
    above = read_sheet(_sheet(tmp_path, HYDROMETER + f"1,{whole + 5:g},20\n2,40,20\n"))
    with pytest.raises(SheetError, match="beyond what the whole sample in suspension reads"):
        check_sheet(above, whole, 0.5)
    check_sheet(read_sheet(EXAMPLE / "hydrometer.csv"), whole, 0.5)    # a real sheet passes


def test_an_inversion_needs_two_cuts_and_a_few_bins(tmp_path):
    one = read_sheet(_sheet(tmp_path, HYDROMETER + "15,28.5,20\n"))
    with pytest.raises(ValueError, match="cut the sample at one diameter only"):
        invert([one], LabTest(), tmp_path / "one")
    with pytest.raises(ValueError, match="give at least 4 size bins"):
        invert([read_sheet(EXAMPLE / "hydrometer.csv")], LabTest(), tmp_path / "bins", bins=1)


def test_a_warmer_day_is_a_longer_test_in_the_reference_water(tmp_path):
    sheet = read_sheet(_sheet(tmp_path, HYDROMETER + "10,40,20\n60,30,25\n"))
    times = effective_times(sheet, Suspension.at_temperature(20.0))
    assert times[0] == pytest.approx(600.0)                  # 20 C throughout the first 10 min
    assert 3600.0 < times[1] < 3600.0 * 1.122                # up to 25 C after: at most 12 % more fall


def test_the_bins_have_an_edge_at_each_readings_cut_diameter():
    from sediment.lab.inverse import MERGE, _penalty, bin_edges

    cuts = np.array([1.0, 1.02, 2.0, 8.0]) * 1e-6
    edges, measured = bin_edges(cuts, 5)
    ratio = 8.0 ** 0.25
    assert measured.sum() == 3 and not measured[-1]              # 1 and 1.02 share one edge; the top one is not a cut
    assert all(np.min(np.abs(np.log(edges[measured] / c))) < np.log(MERGE) for c in cuts)
    assert np.all(np.diff(np.log(edges[:-1])) <= np.log(ratio) + 1e-12)    # no gap wider than the grid's
    assert edges[-1] == pytest.approx(8e-6 * ratio)
    # even bins: the penalty is the shares' second differences
    even = np.geomspace(1e-6, 1e-5, 6)
    rows = _penalty(even)
    assert rows.shape == (len(even) - 3, len(even) + 1)
    assert np.allclose(rows[0, :5], [0, 1, -2, 1, 0])


def test_a_cut_is_the_stokes_diameter_in_dilute_water_and_coarser_where_the_suspension_hinders():
    from sediment.lab.inverse import cut_diameters
    from sediment.lab.sheet import Sheet

    water = Suspension.at_temperature(20.0)
    times = np.array([600.0, 3600.0, 86400.0])
    sheet = Sheet("pipette", Path("p"), times, np.zeros(3), np.full(3, np.nan), np.full(3, 0.10))
    for mass, percent, low, high in [(1e-6, 0.0, 0.995, 1.005), (0.06, 100.0, 1.03, 1.08)]:
        test = LabTest(mass=mass)
        reading = np.full(3, percent / 100 * test.initial_concentration)
        cuts = cut_diameters([sheet], [reading], [times], test, water)
        ratio = cuts / water.stokes_diameter(0.10, times)
        assert np.all((low < ratio) & (ratio < high)), ratio


def test_a_sheet_of_known_answer_is_inverted_closer_than_the_standard_reduction(tmp_path, capsys):
    """Sample 5's sheets (examples/inverse: a 50 000-parcel run in 200 size classes at Courant 1, its
    water warming from 19 to 23 C during the run): the recovered PSD within 0.5 point on average of the
    run's PSD at the readings' diameters and 1.5 at worst anywhere between the finest and the coarsest,
    where the standard ASTM reduction of the same readings is 1.5 points off on average and 3.0 at worst
    (measured: 0.21 and 1.18 for the inverse, benchmarks/invert_validation.py); its band holds the truth
    at most of the readings' diameters (95 % measured)."""
    out = tmp_path / "invert"
    code = cli.main(["invert", *(str(EXAMPLE / f"{name}.csv") for name in ("hydrometer", "pipette", "buoyancy")),
                     "--mass", "0.06", "--out", str(out)])
    assert code == 0
    truth = read_psd(EXAMPLE / "truth_psd.csv")
    rows = np.genfromtxt(out / "psd.csv", delimiter=",", names=True)
    true_percent = truth.at(rows["diameter_um"] * 1e-6)
    error = rows["percent_finer"] - true_percent
    measured = rows["measured"] == 1
    reduction = np.genfromtxt(out / "reduction.csv", delimiter=",", names=True, dtype=None, encoding=None)
    standard = reduction["percent_finer"] - truth.at(reduction["diameter_um"] * 1e-6)
    held = (rows["low"] <= true_percent) & (true_percent <= rows["high"])
    print(f"inverse: mean {np.mean(np.abs(error[measured])):.2f} at the readings' diameters, worst "
          f"{np.max(np.abs(error)):.2f}; standard reduction: mean {np.mean(np.abs(standard)):.2f}, worst "
          f"{np.max(np.abs(standard)):.2f} points; band holds {held[measured].mean():.0%}")
    assert measured.sum() >= 15 and np.mean(np.abs(error[measured])) < 0.5 and np.max(np.abs(error)) < 1.5
    assert np.mean(np.abs(standard)) > 3 * np.mean(np.abs(error[measured]))
    assert held[measured].mean() >= 0.8
    assert np.all(np.diff(rows["percent_finer"]) >= 0) and np.all(rows["low"] <= rows["percent_finer"])
    summary = json.loads((out / "invert.json").read_text())
    assert summary["consistent"] and summary["chi2_per_reading"] < 2
    for name in ("fit.csv", "invert.png"):
        assert (out / name).stat().st_size > 0


def test_a_reader_that_leaves_loses_no_file(tmp_path, monkeypatch):
    """`sediment invert ... | head -1`: the pipe closes after the first line; the command still finishes
    and writes its report, exit 0."""
    import io
    import sys

    class Pipe(io.StringIO):
        def __init__(self, fd: int) -> None:
            super().__init__()
            self.fd = fd

        def write(self, text: str) -> int:
            if "\n" in self.getvalue():
                raise BrokenPipeError(32, "Broken pipe")
            return super().write(text)

        def fileno(self) -> int:
            return self.fd

    with open(tmp_path / "stdout", "w") as sink:
        monkeypatch.setattr(sys, "stdout", Pipe(sink.fileno()))
        code = cli.main(["invert", str(EXAMPLE / "hydrometer.csv"), "--mass", "0.06", "--out", str(tmp_path / "out"),
                         "--particles", "4000"])
    assert code == 0
    assert all((tmp_path / "out" / name).stat().st_size > 0 for name in ("psd.csv", "fit.csv", "invert.json", "invert.png"))


def test_the_design_of_a_test_prefers_early_readings_for_a_steep_coarse_end(tmp_path):
    """Sample 2 (45 % of its mass between 50 and 60 um): the 152H read from 1 min (D7928) recovers it far
    better than from 2 min (D422), whose first reading comes after those grains have passed; a mass beyond
    the 152H's scale is reported as not readable."""
    from sediment.lab.inverse import DESIGNS, design_test

    chosen = {k: DESIGNS[k] for k in ("152H, D422 times", "152H, D7928 times")}
    psd = read_psd(EXAMPLE.parent / "granulometry" / "psd" / "sample2.csv")
    rows = {r[0]: r for r in design_test(psd, tmp_path / "2", masses=(0.060,), designs=chosen, draws=8)}
    assert rows["152H, D7928 times"][4] < 0.5 * rows["152H, D422 times"][4]
    fines = read_psd(EXAMPLE.parent / "granulometry" / "psd" / "sample3.csv")    # 80 g/L of fines: beyond 60 g/L
    (unread,) = design_test(fines, tmp_path / "3", masses=(0.080,), designs={"152H": DESIGNS["152H, D7928 times"]},
                            draws=2)
    assert unread[2] == 0 and np.isnan(unread[4])
