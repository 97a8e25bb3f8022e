# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment invert: sheets a laboratory keeps, refused where no sedimenting suspension reads them, and a
sheet of known answer inverted (docs/inverse.md)."""
from __future__ import annotations

import json
from pathlib import Path

from dataclasses import replace

import numpy as np
import pytest

from sediment import cli
from sediment.inverse import LabTest, effective_times, invert, whole_sample_reading
from sediment.lab.psd import read_psd
from sediment.lab.readout import Suspension
from sediment.lab.sheet import SheetError, check_sheet, read_sheet

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "inverse"
DATA = Path(__file__).resolve().parents[1] / "data"
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
    (HYDROMETER + "1,45,20\n2,40,\n", "no temperature on line(s) 3"),
    (HYDROMETER + "1,1.030,20\n2,1.025,20\n", "look like specific gravities"),
    (HYDROMETER + "1,45,55\n", "temperature_C 55 C is not within 0-40 C"),
    (HYDROMETER + "1,abc,20\n", "reading 'abc' is not a number"),
    ("time_min,depth_cm,mass_g\n1,-10,1\n", "line 2: depth_cm -10 cm is not within 1-200 cm"),
])
def test_sheets_that_cannot_be_a_test_are_refused(tmp_path, text, message):
    with pytest.raises(SheetError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_sheet(_sheet(tmp_path, text))


def test_readings_no_suspension_gives_are_refused(tmp_path):
    test, water = LabTest(0.050), Suspension()    # whole + 5 within the 152H's scale
    rising = read_sheet(_sheet(tmp_path, HYDROMETER + "1,45,20\n2,40,20\n4,42,20\n"))
    whole = whole_sample_reading(rising, test, water)
    with pytest.raises(SheetError, match="line 4, 4 min: the reading .* goes back towards the initial one"):
        check_sheet(rising, whole, 0.5)
    above = read_sheet(_sheet(tmp_path, HYDROMETER + f"1,{whole + 5:g},20\n2,40,20\n"))
    with pytest.raises(SheetError, match="beyond what the whole sample in suspension reads"):
        check_sheet(above, whole, 0.5)
    real = read_sheet(EXAMPLE / "hydrometer.csv")
    check_sheet(real, whole, 0.5, real.reading - real.blank)    # a real sheet passes, after its blank


def test_an_inversion_needs_two_cuts_and_a_few_bins(tmp_path):
    one = read_sheet(_sheet(tmp_path, HYDROMETER + "15,28.5,20\n"))
    with pytest.raises(ValueError, match="cut the sample at one diameter only"):
        invert([one], LabTest(0.060), tmp_path / "one")
    with pytest.raises(ValueError, match="give at least 4 size bins"):
        invert([read_sheet(EXAMPLE / "hydrometer.csv")], LabTest(0.060), tmp_path / "bins", bins=1)


def test_a_warmer_day_is_a_longer_test_in_the_reference_water(tmp_path):
    sheet = read_sheet(_sheet(tmp_path, HYDROMETER + "10,40,20\n60,30,25\n"))
    times = effective_times(sheet, Suspension.at_temperature(20.0))
    assert times[0] == pytest.approx(600.0)                  # 20 C throughout the first 10 min
    assert 3600.0 < times[1] < 3600.0 * 1.122                # up to 25 C after: at most 12 % more fall


def test_the_bins_have_an_edge_at_each_readings_cut_and_sieve_and_tails_above_and_below():
    from sediment.inverse.grid import MERGE, SIEVE_SERIES, size_grid

    cuts = np.array([3.0, 3.05, 6.0, 24.0]) * 1e-6
    grid = size_grid(cuts, 5)
    ratio = 8.0 ** 0.25
    at_cuts = grid.edges[grid.basis == "reading"]
    assert len(at_cuts) == 3                                      # 3 and 3.05 share one edge
    assert all(np.min(np.abs(np.log(at_cuts / c))) < np.log(MERGE) for c in cuts)
    between = (grid.edges >= at_cuts[0]) & (grid.edges <= at_cuts[-1])
    assert np.all(np.diff(np.log(grid.edges[between])) <= np.log(ratio) + 1e-12)    # no gap wider than the grid's
    # the clay limit below the finest cut is a fine-tail edge, and half of it; the sand up to 2 mm is the coarse
    # tail, at the ASTM series and the texture limits; each tail's first edges 1.12 and 1.25 times beyond its cut
    assert list(grid.basis[grid.edges < at_cuts[0]]) == ["fine tail"] * 4
    assert np.allclose(grid.edges[:4], [1e-6, 2e-6, at_cuts[0] / 1.25, at_cuts[0] / 1.12])
    coarse = grid.edges[grid.basis == "coarse tail"]
    assert np.allclose(coarse[:2], at_cuts[-1] * np.array([1.12, 1.25]))
    assert set(SIEVE_SERIES) <= set(coarse) and {50e-6, 63e-6} <= set(coarse)
    assert grid.edges[-1] == 2e-3 and grid.basis[-1] == "top" and grid.floor == pytest.approx(1e-7)
    assert list(grid.tail("fine")) == [0, 1, 2, 3, 4]
    assert grid.tail("coarse")[0] == np.flatnonzero(grid.edges == at_cuts[-1])[0] + 1
    # with a sieve sheet the sieves pin the coarse end: no series, no tail but the top bin
    sieves = np.array([75e-6, 150e-6, 425e-6])
    pinned = size_grid(cuts, 5, sieves, top=850e-6)
    assert set(sieves) <= set(pinned.edges[pinned.basis == "sieve"]) and 250e-6 not in pinned.edges
    assert list(pinned.tail("coarse")) == [pinned.bins - 1] and pinned.edges[-1] == 850e-6
    with pytest.raises(ValueError, match="at or above its largest grain"):
        size_grid(cuts, 5, top=24.5e-6)


def test_the_penalty_is_the_shares_second_differences_on_even_bins_and_leaves_the_tails_free():
    from sediment.inverse.fit import penalty
    from sediment.inverse.grid import SizeGrid

    edges = np.geomspace(1e-6, 1e-5, 6)
    grid = SizeGrid(np.append(edges, 1e-4), np.array(["reading"] * 6 + ["top"]), 1e-7)
    rows = penalty(grid)
    assert rows.shape == (3, 7)                 # bins 1-5 lie between the pinned edges: three triples
    assert np.allclose(rows[0, :5], [0, 1, -2, 1, 0])
    assert np.all(rows[:, [0, 6]] == 0)         # the tails (below the first, above the last edge) are free


def test_a_cut_is_the_stokes_diameter_in_dilute_water_and_coarser_where_the_suspension_hinders():
    from sediment.inverse.model import cut_diameters
    from sediment.lab.sheet import Sheet

    water = Suspension.at_temperature(20.0)
    times = np.array([600.0, 3600.0, 86400.0])
    sheet = Sheet("pipette", Path("p"), times, np.zeros(3), np.full(3, np.nan), np.full(3, 0.10))
    for mass, percent, low, high in [(1e-6, 0.0, 0.995, 1.005), (0.06, 100.0, 1.03, 1.08)]:
        test = LabTest(mass)
        reading = np.full(3, percent / 100 * test.initial_concentration)
        cuts = cut_diameters([replace(sheet, reading=reading)], [times], test, water)
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
    inside = (rows["diameter_um"] >= rows["diameter_um"][measured][0]) & (rows["diameter_um"] <= rows["diameter_um"][measured][-1])
    reduction = np.genfromtxt(out / "reduction.csv", delimiter=",", names=True, dtype=None, encoding=None)
    standard = reduction["percent_finer"] - truth.at(reduction["diameter_um"] * 1e-6)
    held = (rows["low"] <= true_percent) & (true_percent <= rows["high"])
    print(f"inverse: mean {np.mean(np.abs(error[measured])):.2f} at the readings' diameters, worst "
          f"{np.max(np.abs(error[inside])):.2f}; standard reduction: mean {np.mean(np.abs(standard)):.2f}, worst "
          f"{np.max(np.abs(standard)):.2f} points; band holds {held[measured].mean():.0%}")
    assert measured.sum() >= 15 and np.mean(np.abs(error[measured])) < 0.5 and np.max(np.abs(error[inside])) < 1.5
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
    from sediment.inverse import DESIGNS, design_test

    chosen = {k: DESIGNS[k] for k in ("152H, D422 times", "152H, D7928 times")}
    psd = read_psd(EXAMPLE.parent / "granulometry" / "psd" / "sample2.csv")
    rows = {r[0]: r for r in design_test(psd, tmp_path / "2", masses=(0.060,), designs=chosen, draws=8)}
    assert rows["152H, D7928 times"][4] < 0.5 * rows["152H, D422 times"][4]
    fines = read_psd(EXAMPLE.parent / "granulometry" / "psd" / "sample3.csv")    # 80 g/L of fines: beyond 60 g/L
    (unread,) = design_test(fines, tmp_path / "3", masses=(0.080,), designs={"152H": DESIGNS["152H, D7928 times"]},
                            draws=2)
    assert unread[2] == 0 and np.isnan(unread[4])


SIEVE = "opening_mm,percent_passing\n"


@pytest.mark.parametrize("text, message", [
    (SIEVE + "0.075,40\n0.15,45\n0.15,50\n", "opening 0.15 mm appears twice"),
    (SIEVE + "75,40\n150,60\n2000,100\n", "write the openings in millimetres"),
    (SIEVE + "0.075,0.4\n0.15,0.6\n2,1\n", "not fractions"),
    (SIEVE + "0.075,60\n0.15,55\n2,100\n", "more passes the 0.075 mm sieve"),
    (SIEVE + "0.075,-1\n2,100\n", "within 0-100"),
    ("time_min,reading,temperature_C,opening_mm,percent_passing\n1,40,20,2,100\n", "give each instrument a sheet"),
    (HYDROMETER.strip() + ",blank\n1,45,20,2\n2,40,20,\n", "no blank on line(s) 3"),
    (HYDROMETER.strip() + ",Blank\n1,45,20,2\n2,40,20,2\n", "column(s) Blank are not of a hydrometer sheet"),
    ("opening_mm;percent_passing\n0,075;40\n2;100\n", "separated by ';'"),
    (SIEVE + "75,40\n106,60\n150,100\n", "the finest sieve is 75 mm"),
])
def test_sieve_sheets_and_blank_columns_that_cannot_be_are_refused(tmp_path, text, message):
    with pytest.raises(SheetError, match=message.replace("(", r"\(").replace(")", r"\)")):
        read_sheet(_sheet(tmp_path, text))


def test_a_sieve_sheet_is_read_in_any_order_and_a_blank_is_subtracted(tmp_path):
    from sediment.lab.sheet import SieveSheet

    sieve = read_sheet(_sheet(tmp_path, "\ufeff" + SIEVE.replace("\n", ",\n") + "2.0,100,\n0.425,80,\n0.075,52.5,\n",
                              "s.csv"))    # a spreadsheet's BOM and trailing empty column
    assert isinstance(sieve, SieveSheet)
    assert np.allclose(sieve.opening, [75e-6, 425e-6, 2e-3]) and list(sieve.passing) == [52.5, 80, 100]
    sheet = read_sheet(_sheet(tmp_path, HYDROMETER.strip() + ",blank\n1,45,20,2\n2,40,21,1.5\n", "h.csv"))
    assert list(LabTest(0.05, zero_correction=9.0).corrected(sheet)) == [43.0, 38.5]    # the column wins


def test_what_the_sieves_say_of_the_specimen(tmp_path):
    from sediment.inverse.invert import sieve_data

    whole = read_sheet(_sheet(tmp_path, SIEVE + "4.75,100\n2.0,80\n0.425,60\n0.075,40\n"))
    plain = sieve_data(whole, None, 0.5)
    assert plain.top == 4.75e-3 and plain.share == 1 and list(plain.percent) == [40, 60, 80]
    split = sieve_data(whole, 2e-3, 0.5)    # D422: the hydrometer tests the part passing 2 mm
    assert split.top == 2e-3 and split.share == 0.8 and np.allclose(split.percent, [50, 75])
    assert np.allclose(split.sigma, 0.625)
    short = read_sheet(_sheet(tmp_path, SIEVE + "2.0,95\n0.075,40\n", "short.csv"))
    with pytest.raises(SheetError, match="passes the largest sieve .* --split"):
        sieve_data(short, None, 0.5)
    with pytest.raises(SheetError, match="no sieve of 0.85 mm"):
        sieve_data(short, 0.85e-3, 0.5)
    with pytest.raises(ValueError, match="--split needs the sieve sheet"):
        sieve_data(None, 2e-3, 0.5)


@pytest.mark.parametrize("extra, message", [
    (["h.csv"], "--mass is required"),
    (["h.csv", "--mass", "0.05", "--zero-correction", "2"], "the composite correction is given twice"),
    (["h.csv", "copy.csv", "--mass", "0.05"], "hold the same readings"),
    (["h.csv", "crlf.csv", "--mass", "0.05"], "hold the same readings"),
    (["h.csv", "--mass", "0.05", "--split", "2"], "--split needs the sieve sheet"),
    (["big_blank.csv", "--mass", "0.05"], "is larger than the reading"),
])
def test_what_the_command_refuses_to_guess(tmp_path, capsys, extra, message):
    sheet = HYDROMETER.strip() + ",blank\n1,45,20,2\n2,40,20,2\n"
    _sheet(tmp_path, sheet, "h.csv")
    _sheet(tmp_path, sheet, "copy.csv")
    (tmp_path / "crlf.csv").write_bytes(sheet.replace("\n", "\r\n").encode())    # the same sheet saved on Windows
    _sheet(tmp_path, HYDROMETER.strip() + ",blank\n1,45,20,2\n2,15,20,18\n", "big_blank.csv")
    args = [str(tmp_path / a) if a.endswith(".csv") else a for a in extra]
    code = cli.main(["invert", *args, "--out", str(tmp_path / "out")])
    assert code != 0 and message in capsys.readouterr().err
    assert not (tmp_path / "out" / "psd.csv").exists()


def test_the_inverse_psd_is_read_wherever_a_psd_is_and_one_that_does_not_fit_is_not(tmp_path):
    from sediment.lab.psd import PSDError

    table = ("diameter_um,percent_finer,low,high,measured,basis\n0.2,0,0,30,0,floor\n2,30,28,32,1,reading\n"
             "75,60,58,62,1,sieve\n850,100,100,100,0,top\n")
    psd = read_psd(_sheet(tmp_path, table, "psd.csv"))
    assert psd.at([2e-6])[0] == 30 and psd.span() == (0.2e-6, 850e-6)
    with pytest.raises(PSDError, match="does not explain its sheets"):
        read_psd(_sheet(tmp_path, "# NOT CONSISTENT: these files ...\n" + table, "bad.csv"))


SOIL = EXAMPLE / "soil"


def _recovered(out: Path):
    rows = np.genfromtxt(out / "psd.csv", delimiter=",", names=True, dtype=None, encoding=None)
    truth = read_psd(SOIL / "truth_psd.csv").at(rows["diameter_um"] * 1e-6)
    return rows, truth


def _usda_truth() -> dict:
    from sediment.lab.texture import fractions

    fine = np.geomspace(0.05e-6, 3e-3, 600)
    return fractions(fine, read_psd(SOIL / "truth_psd.csv").at(fine), "USDA")


def test_a_soil_with_its_sieve_sheet_is_pinned_at_the_sieves_and_its_texture_comes_out(tmp_path, capsys):
    """examples/inverse/soil (a clay loam with sand to 2 mm: the 152H with a blank column and the sieves
    of the same sample): within 1 point of the truth at every sieve and within 1.2 at every reading's cut;
    USDA clay, silt and sand within 1.5 points. Without the sieve rows in the fit the coarse end is only
    the tail's even placement, several points off at 250-850 um (docs/inverse.md, the soils' table)."""
    out = tmp_path / "soil"
    code = cli.main(["invert", str(SOIL / "hydrometer.csv"), str(SOIL / "sieve.csv"), "--mass", "0.05", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0 and printed.rstrip().splitlines()[-1].startswith("verdict: fits")
    rows, truth = _recovered(out)
    error = rows["percent_finer"] - truth
    assert np.all(np.abs(error[rows["basis"] == "sieve"]) < 1.0), error[rows["basis"] == "sieve"]
    assert np.all(np.abs(error[rows["basis"] == "reading"]) < 1.2), error[rows["basis"] == "reading"]
    texture = np.genfromtxt(out / "texture.csv", delimiter=",", names=True, dtype=None, encoding=None)
    truth_usda = _usda_truth()
    for fraction in ("clay", "silt", "sand"):
        (row,) = texture[(texture["system"] == "USDA") & (texture["fraction"] == fraction)]
        assert abs(row["percent"] - truth_usda[fraction]) < 1.5, (fraction, row, truth_usda[fraction])
    summary = json.loads((out / "invert.json").read_text())
    assert summary["inputs"]["mass"] == 0.05 and list(summary["inputs"]["composite_correction"].values()) == ["blank column"]
    assert summary["texture"]["usda_class"] == "clay loam"
    assert read_psd(out / "psd.csv").span()[1] == pytest.approx(2e-3)    # sample and plan take invert's PSD
    for name in ("gradation.csv", "gradation.png", "texture.png"):
        assert (out / name).stat().st_size > 0


def test_without_sieves_the_coarse_end_is_an_unknown_whose_band_holds_the_truth(tmp_path):
    """The same 152H sheet alone: the sand's placement above the coarsest cut is open, so the band runs
    from the coarsest cut up to 2 mm and holds the truth at the cut and at every edge above it; where it
    does not (the old single bin just above the cut), the cut was 4.5 points low with a band excluding
    the truth (issue 57)."""
    from sediment.inverse import LabTest

    result = invert([read_sheet(SOIL / "hydrometer.csv")], LabTest(0.05), tmp_path / "runs", draws=32)
    truth = read_psd(SOIL / "truth_psd.csv").at(result.diameter)
    coarse = result.basis == "coarse tail"
    coarsest = np.flatnonzero(result.basis == "reading")[-1]
    assert result.diameter[coarse].max() == pytest.approx(850e-6) and result.diameter[-1] == 2e-3
    assert result.low[coarsest] <= truth[coarsest] <= result.high[coarsest]
    held = (result.low - 0.05 <= truth) & (truth <= result.high + 0.05)
    assert held[coarse].all(), np.c_[result.diameter[coarse] * 1e6, result.low[coarse], truth[coarse], result.high[coarse]]
    assert np.all(result.high[coarse][-3:] - result.low[coarse][-3:] > 15)    # the placement is open, and says so


def test_design_says_when_the_152h_reaches_the_clay_limit():
    """A 2 um grain's Stokes time to the bulb's depth at the reading the PSD gives there: between 10 and 15 h
    at 20 C for a 152H (Stokes depths 10-16 cm), shorter in warmer water by the viscosity's ratio."""
    from sediment.inverse import clay_reading_time

    times = dict(clay_reading_time(read_psd(EXAMPLE / "soils" / "clay_loam.csv"), LabTest(0.05)))
    assert 10 * 3600 < times[20.0] < 15 * 3600
    water = {t: Suspension.at_temperature(t).viscosity for t in (20.0, 25.0)}
    assert times[25.0] / times[20.0] == pytest.approx(water[25.0] / water[20.0], rel=0.01)


def test_sheets_no_psd_explains_are_fitted_as_well_as_they_can_be_and_marked_so(tmp_path, capsys):
    """The soil's 152H sheet with a sieve sheet of another sample (40 % passing 75 um, where the hydrometer
    reads 70 % finer at 46 um): exit 3, the verdict last and the sieve named, every table's first line
    saying so, and its psd.csv refused as a PSD."""
    from sediment.lab.psd import PSDError

    sieve = _sheet(tmp_path, SIEVE + "2.0,100\n0.425,70\n0.15,50\n0.075,40\n", "other_sieve.csv")
    out = tmp_path / "out"
    code = cli.main(["invert", str(SOIL / "hydrometer.csv"), str(sieve), "--mass", "0.05", "--out", str(out)])
    printed = capsys.readouterr().out.rstrip().splitlines()
    assert code == 3 and printed[-1].startswith("verdict: NOT CONSISTENT")
    assert any(line.startswith("sieve at 0.075 mm is") for line in printed)
    for name in ("psd.csv", "texture.csv", "gradation.csv", "fit.csv", "reduction.csv"):
        assert (out / name).read_text().startswith("# NOT CONSISTENT"), name
    assert (out / "texture.png").stat().st_size > 0 and not json.loads((out / "invert.json").read_text())["consistent"]
    with pytest.raises(PSDError, match="does not explain its sheets"):
        read_psd(out / "psd.csv")


def test_the_design_of_a_test_from_the_command_line(tmp_path, capsys):
    """`invert --design` with one mass and few parcels: the table, the clay limit's time, the figure."""
    out = tmp_path / "design"
    code = cli.main(["invert", "--design", str(EXAMPLE / "soils" / "clay_loam.csv"), "--masses", "0.05", "--particles",
                     "3000", "--out", str(out)])
    printed = capsys.readouterr().out
    assert code == 0 and "the 152H's cut reaches 2 um (clay) after: 18 C:" in printed
    assert (out / "design.csv").read_text().startswith("design,mass_g,readings") and (out / "design.png").exists()


def test_the_corrections_name_every_effect_and_add_up_to_the_difference(tmp_path, capsys):
    """corrections.csv and invert.json: at each reading's standard diameter the inverse's percent finer is
    the standard reduction's plus the change each effect makes when switched on after the ones before it
    (the fit, the temperature record, the drag curve, the instrument's body, the hindrance), to rounding;
    the inverse's percent there is psd.csv's. No effect is a copy of the one before it: each moves some
    reading (this 60 g test's water warms 4 C, its coarsest cut is 50 um, its bulb averages 14 cm)."""
    from sediment.inverse.breakdown import EFFECTS

    out = tmp_path / "invert"
    code = cli.main(["invert", str(EXAMPLE / "hydrometer.csv"), str(EXAMPLE / "pipette.csv"), "--mass", "0.06",
                     "--particles", "4000", "--out", str(out)])
    assert code == 0
    assert "against the standard reduction at its diameters:" in capsys.readouterr().out
    header = (out / "corrections.csv").read_text().splitlines()[0].split(",")
    assert header[4:9] == [e.replace(" ", "_") for e in EFFECTS] == ["fit", "temperature_record", "drag_curve",
                                                                      "instrument_body", "hindrance"]
    corrections = json.loads((out / "invert.json").read_text())["corrections"]
    rows = corrections["rows"]
    assert len(rows) == 8 + 5    # every reading of both sheets
    for row in rows:
        assert row["standard_percent"] + sum(row["changes"].values()) == pytest.approx(row["inverse_percent"], abs=1e-9)
        assert row["band"][0] - 1e-9 <= row["inverse_percent"] <= row["band"][1] + 1e-9
    psd = np.genfromtxt(out / "psd.csv", delimiter=",", names=True)
    at = np.array([r["diameter_um"] for r in rows])
    assert np.interp(np.log(at), np.log(psd["diameter_um"]), psd["percent_finer"]) == \
        pytest.approx([r["inverse_percent"] for r in rows], abs=0.01)
    for effect in EFFECTS:
        assert max(abs(r["changes"][effect]) for r in rows) > 0.005, effect
    assert corrections["total"]["mean"] == pytest.approx(np.mean([r["inverse_percent"] - r["standard_percent"]
                                                                  for r in rows]))


def test_a_fines_only_sheet_without_sieves_has_a_band_that_allows_no_sand(tmp_path):
    """A 152H sheet alone of fines with 95 % between 50 and 70 um, its first reading cutting at 52 um
    (tests/data/fines_mode_above_cut). The sheet cannot say how the mode lies above the cut: the band at
    every cut holds the truth, and at 75 um it reaches 100 % (the answer with no sand, which the readings
    allow). Without the narrow bins just beyond the cut the band there missed the truth by 3 points."""
    data = Path(__file__).resolve().parents[1] / "data" / "fines_mode_above_cut"
    out = tmp_path / "invert"
    assert cli.main(["invert", str(data / "hydrometer.csv"), "--mass", "0.06", "--particles", "6000",
                     "--out", str(out)]) == 0
    rows = np.genfromtxt(out / "psd.csv", delimiter=",", names=True, dtype=None, encoding=None)
    truth = read_psd(data / "truth_psd.csv").at(rows["diameter_um"] * 1e-6)
    cut = np.flatnonzero(rows["basis"] == "reading")
    held = (rows["low"] - 0.01 <= truth) & (truth <= rows["high"] + 0.01)
    assert held[cut].all(), list(zip(rows["diameter_um"][cut], rows["low"][cut], truth[cut], rows["high"][cut]))
    assert np.interp(np.log(75.0), np.log(rows["diameter_um"]), rows["high"]) == pytest.approx(100.0, abs=0.01)


def test_a_split_that_the_specimen_did_not_pass_is_noted(tmp_path, capsys):
    """The clay loam's specimen passed 2 mm, its readings' coarsest cut is 45 um and 74 % of it passes 75
    um: `--split 0.075` says the specimen was the part passing 75 um, and the fit makes up the difference
    with a 32-point step between the cut and the split sieve, which the note names (it skipped the split
    sieve before). Without the wrong split, no note."""
    soil = EXAMPLE / "soil"
    argv = ["invert", str(soil / "hydrometer.csv"), str(soil / "sieve.csv"), "--mass", "0.05", "--particles", "4000"]
    assert cli.main(argv + ["--split", "0.075", "--out", str(tmp_path / "split")]) == 0
    assert "check: the curve rises by" in capsys.readouterr().out
    assert cli.main(argv + ["--out", str(tmp_path / "plain")]) == 0
    printed = capsys.readouterr().out
    assert "check: the curve rises" not in printed and "pull the curve apart" not in printed


def test_readings_far_closer_to_the_fit_than_their_errors_are_noted(tmp_path, capsys):
    """The clay loam's 152H sheet written as a 151H's 1000 (G - 1) (0.6226 R) and given as a 152H's: it fits, at a
    chi-square per reading of about 0.02 (0.06 as the 152H it is), and the note names both readings of that;
    with its sieves, the step to the 75 um sieve names the unit."""
    lines = (SOIL / "hydrometer.csv").read_text().splitlines()
    head = lines[0].split(",")
    scaled = [",".join(f"{0.6226 * float(v):.1f}" if name in ("reading", "blank") else v
                       for name, v in zip(head, line.split(","))) for line in lines[1:]]
    sheet = tmp_path / "as_151h.csv"
    sheet.write_text("\n".join([lines[0], *scaled]) + "\n")
    assert cli.main(["invert", str(sheet), "--mass", "0.05", "--out", str(tmp_path / "alone")]) == 0
    printed = capsys.readouterr().out
    assert "lie far closer to the fit than their stated errors say" in printed and "--hydrometer-type 151H" in printed
    assert cli.main(["invert", str(sheet), str(SOIL / "sieve.csv"), "--mass", "0.05", "--particles", "4000",
                     "--out", str(tmp_path / "sieved")]) == 0
    assert "a 151H's as a 152H's" in capsys.readouterr().out


def test_a_sieve_sheet_of_another_soil_is_noted(tmp_path, capsys):
    """The clay loam's 152H with the sieves of a clay (84 % passing 75 um, not 74): the fit takes a 10-point
    step between the coarsest cut (45 um) and the 75 um sieve, under the step note's, and fits (chi-square
    per reading 0.9); but its first reading and the 75 um sieve are each over 2 noise units off the fit, the
    other way each, which the note names."""
    argv = ["invert", str(EXAMPLE / "soil" / "hydrometer.csv"), str(DATA / "sieve_of_another_soil.csv"), "--mass", "0.05",
            "--particles", "4000", "--out", str(tmp_path / "other")]
    assert cli.main(argv) == 0
    printed = capsys.readouterr().out
    assert "the hydrometer's first reading (1 min" in printed and "0.075 mm sieve" in printed
    assert "pull the curve apart" in printed and "a sieve sheet of another sample" in printed


@pytest.mark.parametrize("totals, message", [
    ({"pipette": 0.5}, "no physical total for the hydrometer (it has pipette)"),
    ({"hydrometer": 1e300}, "are not points of percent finer"),
])
def test_a_budget_that_is_not_this_tests_is_refused_before_the_inversion(tmp_path, capsys, totals, message):
    budget = tmp_path / "budget.json"
    budget.write_text(json.dumps([{"sample": "other", "physical_total_pp": totals}]))
    assert cli.main(["invert", str(EXAMPLE / "soil" / "hydrometer.csv"), "--mass", "0.05", "--budget", str(budget),
                     "--out", str(tmp_path / "out")]) == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_budget_of_another_test_is_named_and_recorded(tmp_path, capsys):
    """A budget made for sample 5 (its PSD 40-50 points off the clay loam's at 2-20 um) widens the band, and the
    note names its sample and how far its PSD is from the one recovered; one made for the clay loam itself
    (its truth) at its mass gets no note; invert.json records which budget, by its SHA-256."""
    from sediment.lab.psd import read_psd as psd_of

    def budget(name: str, psd, mass: float) -> Path:
        path = tmp_path / f"{name}.json"
        made_for = {"diameter_um": (psd.diameter * 1e6).tolist(), "percent_finer": psd.percent_finer.tolist(),
                    "mass_kg": mass, "temperature_C": 20.0}
        path.write_text(json.dumps([{"sample": name, "physical_total_pp": {"hydrometer": 1.0}, "made_for": made_for}]))
        return path
    argv = ["invert", str(SOIL / "hydrometer.csv"), str(SOIL / "sieve.csv"), "--mass", "0.05", "--particles", "4000"]
    other = budget("sample5", psd_of(EXAMPLE.parent / "granulometry" / "psd" / "sample5.csv"), 0.06)
    assert cli.main(argv + ["--budget", str(other), "--out", str(tmp_path / "other")]) == 0
    printed = capsys.readouterr().out
    assert "(sample 'sample5') was made for another test: its PSD is" in printed
    recorded = json.loads((tmp_path / "other" / "invert.json").read_text())["inputs"]["budget"]
    assert recorded["sample"] == "sample5" and len(recorded["sha256"]) == 64 and recorded["made_for"]["mass_kg"] == 0.06
    own = budget("clay_loam", psd_of(SOIL / "truth_psd.csv"), 0.05)
    assert cli.main(argv + ["--budget", str(own), "--out", str(tmp_path / "own")]) == 0
    assert "was made for another test" not in capsys.readouterr().out


def test_a_gravelly_sieve_sheet_without_a_split_names_the_split(tmp_path, capsys):
    """A whole-sample sieve sheet into gravel (all of it passes 25 mm only) without --split: no column of the
    test holds its grains, and the refusal names --split 2.0 (it said only that 0.36 m is not tall enough)."""
    sieve = tmp_path / "gravelly.csv"
    sieve.write_text("opening_mm,percent_passing\n25,100\n19,96\n9.5,90\n4.75,86\n2,82\n0.85,78\n0.425,72\n0.25,66\n"
                     "0.15,60\n0.075,52\n")
    assert cli.main(["invert", str(SOIL / "hydrometer.csv"), str(sieve), "--mass", "0.05",
                     "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert "passes only the 25 mm sieve" in err and "which 82 % passes" in err and "give --split 2.0" in err
    assert not (tmp_path / "out").exists()
