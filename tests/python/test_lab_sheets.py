# SPDX-License-Identifier: GPL-2.0-or-later
"""A laboratory's sheets as it keeps them (docs/inverse.md): its own calibrated 152H and cylinders, clock
times, air-dry masses, two-reading protocols and batches, on the six Penn State D7928 records of
examples/inverse/real-lab (published with the R package soiltestr, MIT; provenance in its README)."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from sediment.cli import main
from sediment.inverse.model import LabTest
from sediment.lab.instruments import INSTRUMENTS
from sediment.lab.instruments import HYDROMETERS
from sediment.lab.readout import Column, Hydrometer, Suspension
from sediment.lab.sheet import SheetError, read_hydrometer_calibration, read_sheet, standard_reduction

REPO = Path(__file__).resolve().parents[2]
REAL = REPO / "examples" / "inverse" / "real-lab"
SAMPLES = sorted(p for p in REAL.iterdir() if p.is_dir())
REDUCED = [p for p in SAMPLES if (p / "reference_reduction.csv").exists()]    # the laboratory's own reduction
CALIBRATION = REAL / "hydrometer_1.csv"
LAB = ["--hydrometer-calibration", str(CALIBRATION), "--bulb-volume", "55e-6", "--bulb-length", "0.137",
       "--particle-density", "2700", "--meniscus", "1"]


def _lab_test(sample: Path, meniscus: float) -> tuple[LabTest, Hydrometer]:
    options = json.loads((sample / "sample.json").read_text())
    hydrometer = Hydrometer.calibrated(*read_hydrometer_calibration(CALIBRATION), 55e-6, 0.137)
    mass = options["air-dry-mass"] / (1 + options["water-content"])
    area = options["cylinder-area"]
    return LabTest(mass, 2700.0, area, 1e-3 / area, hydrometer=hydrometer, meniscus=meniscus), hydrometer


@pytest.mark.parametrize("sample", REDUCED, ids=[p.name for p in REDUCED])
def test_the_standard_reduction_with_the_laboratorys_apparatus_is_the_laboratorys(sample):
    """Percent finer within 0.2 points and diameters within 1.5 % of the laboratory's own reduction at every
    reading, with its calibration, cylinder, air-dry mass and the meniscus as its code applies it (the
    calibration read at R - C_m: --meniscus -1); D422's R + C_m puts the bulb 2 C_m x 0.18 cm higher."""
    sheet = read_sheet(sample / "hydrometer.csv")
    reference = np.genfromtxt(sample / "reference_reduction.csv", delimiter=",", names=True)
    test, hydrometer = _lab_test(sample, -1.0)
    water = Suspension.at_temperature(float(np.mean(sheet.temperature)), 2700.0)
    reduced = standard_reduction(sheet, water, test.initial_concentration, hydrometer, test.cylinder_area, test.sphere,
                                 test.meniscus, test.correction(sheet))
    assert np.max(np.abs(reduced.percent - reference["percent_finer"])) < 0.2
    assert np.max(np.abs(reduced.diameter * 1e6 / reference["diameter_um"] - 1)) < 0.015
    assert np.allclose(reduced.depth * 100, reference["Hm_cm"], atol=1e-3)
    d422 = standard_reduction(sheet, water, test.initial_concentration, hydrometer, test.cylinder_area, test.sphere,
                              1.0, test.correction(sheet))
    assert np.allclose(reduced.depth - d422.depth, 2 * (0.203 - 0.086) / 65, atol=1e-9)


def test_the_forward_152h_reads_nothing_in_the_companion_cylinders_liquid():
    """The model's 152H floats in the blank's liquid (water and dispersant at the reading's temperature): a
    column without solids reads 0 after the composite correction, at 22 C as at 20 C, for any blank and
    meniscus. In the run's water alone it read -0.7 g/L at 22 C, which the fit made up with mass."""
    sheet = read_sheet(SAMPLES[0] / "hydrometer.csv")
    test, _ = _lab_test(SAMPLES[0], 1.0)
    water = Suspension.at_temperature(22.0, 2700.0)
    column = Column(np.linspace(0.0, test.height, 41), np.array([0.0, 2e5]), np.zeros((2, 40)), water)
    assert np.allclose(INSTRUMENTS["hydrometer"].modelled(column, sheet, sheet.time, test, water), 0.0, atol=1e-9)


@pytest.mark.parametrize("text, message", [
    ("reading,distance_cm\n-5,20.3\n", "at least two readings"),
    ("reading,distance_cm\n-5,20.3\n60,8.6\n30,21\n", "does not fall from reading -5 (20.3 cm) to 30 (21 cm)"),
    ("reading,distance_cm\n-5,20.3\n-5,19\n", "the reading -5 is calibrated twice"),
    ("reading,distance_cm\n-5,203\n60,86\n", "written in mm? that is 20.3 cm"),
    ("reading,distance\n-5,20.3\n60,8.6\n", "needs the columns reading,distance_cm"),
])
def test_a_calibration_that_cannot_be_is_refused(tmp_path, text, message):
    path = tmp_path / "cal.csv"
    path.write_text(text)
    with pytest.raises(SheetError, match=message.replace("(", r"\(").replace(")", r"\)").replace("?", r"\?")):
        read_hydrometer_calibration(path)


def test_a_graduation_inside_the_bulb_is_refused():
    with pytest.raises(ValueError, match="inside a bulb of 14 cm"):
        Hydrometer.calibrated([0.0, 60.0], [0.15, 0.05])


def test_a_calibration_is_read_linear_between_and_beyond_its_rows():
    h = Hydrometer.calibrated([-5.0, 20.0, 60.0], [0.203, 0.16, 0.086])
    assert h.centre_distance(np.array([-5.0, 7.5, 20.0, 60.0])) == pytest.approx([0.203, 0.1815, 0.16, 0.086])
    assert h.centre_distance(70.0) == pytest.approx(0.086 - 10 * 0.074 / 40)
    assert h.centre_distance(-10.0) == pytest.approx(0.203 + 5 * 0.043 / 25)


def _as_151h(text: str) -> str:
    """A 152H sheet or calibration as a 151H on the same stem reads it: 1 + 0.6226 R / 1000."""
    rows = [line.split(",") for line in text.strip().splitlines()]
    columns = [k for k, name in enumerate(rows[0]) if name in ("reading", "blank")]
    for row in rows[1:]:
        for k in columns:
            row[k] = f"{1 + float(row[k]) * (1 - 1 / 2.65) / 1000:.7f}"
    return "\n".join(",".join(row) for row in rows) + "\n"


def test_a_151h_sheet_reduces_as_d422_says_and_as_the_same_stems_152h(tmp_path):
    """The 151H reads specific gravity on the 152H's stem (D422 3.2): its sheet reduces to D422's percent
    finer, 100 000 / W x G / (G - 1) x (R - R_blank), and to the 152H's diameters; the nominal 151H's
    effective depth is D422's table (16.3 cm at 1.000, 11.0 at 1.020, 8.1 at 1.031, read to 0.1 cm)."""
    sample = SAMPLES[0]
    sheet151 = tmp_path / "hydrometer.csv"
    sheet151.write_text(_as_151h((sample / "hydrometer.csv").read_text()))
    calibration151 = tmp_path / "calibration.csv"
    calibration151.write_text(_as_151h(CALIBRATION.read_text()))
    test, hydrometer = _lab_test(sample, 1.0)
    water = Suspension.at_temperature(22.0, 2700.0)
    raw = np.genfromtxt(sheet151, delimiter=",", names=True)
    reductions = []
    for sheet, calibration in ((read_sheet(sample / "hydrometer.csv"), CALIBRATION),
                               (read_sheet(sheet151, hydrometer_type="151H"), calibration151)):
        instrument = Hydrometer.calibrated(*read_hydrometer_calibration(calibration, sheet.scale.name), 55e-6, 0.137)
        reductions.append(standard_reduction(sheet, water, test.initial_concentration, instrument, test.cylinder_area,
                                             test.sphere, test.meniscus, test.correction(sheet)))
    gs = 2.7
    d422 = 1e5 / (test.mass * 1e3) * gs / (gs - 1) * (raw["reading"] - raw["blank"])
    assert np.allclose(reductions[1].percent, d422, atol=1e-9)
    assert np.allclose(reductions[1].percent, reductions[0].percent, atol=1e-3)
    assert np.allclose(reductions[1].diameter, reductions[0].diameter, rtol=1e-5)
    nominal = Hydrometer.astm_152h()
    depth = nominal.effective_depth(HYDROMETERS["151H"].scale.grams([1.000, 1.020, 1.031])) * 100
    assert depth == pytest.approx([16.3, 11.0, 8.1], abs=0.1)


def test_a_sheet_on_the_other_hydrometers_scale_is_refused_naming_the_option(tmp_path, capsys):
    sample = SAMPLES[0]
    sheet151 = tmp_path / "hydrometer.csv"
    sheet151.write_text(_as_151h((sample / "hydrometer.csv").read_text()))
    with pytest.raises(SheetError, match="look like specific gravities: a 151H's sheet needs --hydrometer-type 151H"):
        read_sheet(sheet151)
    with pytest.raises(SheetError, match="look like a 152H's g/L, not the specific gravities of a 151H"):
        read_sheet(sample / "hydrometer.csv", hydrometer_type="151H")
    high = tmp_path / "high.csv"
    high.write_text("time_min,reading,temperature_C\n1,1.045,20\n")
    with pytest.raises(SheetError, match="line 2: reading 1.045 is not within 0.995-1.04: a 151H's scale"):
        read_sheet(high, hydrometer_type="151H")
    blank = tmp_path / "blank.csv"
    blank.write_text("time_min,reading,temperature_C,blank\n1,1.02,20,0.004\n")
    with pytest.raises(SheetError, match="blank 0.004 is not within 0.99-1.0125: a 151H in the control cylinder"):
        read_sheet(blank, hydrometer_type="151H")
    out = ["--mass", "0.025", "--hydrometer-type", "151H", "--out", str(tmp_path / "out")]
    assert "--meniscus 0.05 (151H) as a 152H's: 80.303 g/L is not within -5 to 5 g/L" in _refusal(
        capsys, ["invert", str(sheet151), *out, "--meniscus", "0.05"])
    assert "written in a 152H's g/L? with --hydrometer-type 151H give it in specific gravity: 0.000623" in _refusal(
        capsys, ["invert", str(sheet151), *out, "--meniscus", "1"])
    assert "--hydrometer-noise 0 (151H) as a 152H's: 0 g/L is not within" in _refusal(
        capsys, ["invert", str(sheet151), *out, "--hydrometer-noise", "0"])
    # a 151H's rise is quoted as read, with its reading error in its own unit
    risen = tmp_path / "risen.csv"
    risen.write_text(sheet151.read_text().replace("598.0,1.0087170", "598.0,1.0098000"))
    message = _refusal(capsys, ["invert", str(risen), *out])
    assert "line 8, 598 min: the reading (1.0098 (15.7 g/L of a 152H) on the sheet" in message
    assert "--hydrometer-noise (now 0.000156 in specific gravity (0.25 g/L of a 152H)" in message


def test_clock_times_count_from_the_stirring_and_past_midnight(tmp_path):
    sheet = tmp_path / "h.csv"
    sheet.write_text("clock,reading,temperature_C\n23:51,30,22\n23:55,28,22\n00:10,27,22\n02:00,25,22\n23:40,20,22\n")
    assert read_sheet(sheet, stirred="23:50").time / 60 == pytest.approx([1, 5, 20, 130, 1430])
    sheet.write_text("clock,reading,temperature_C\n09:01,30,22\n09:05,28,22\n09:03,27,22\n")
    with pytest.raises(SheetError, match="line 4: the clock goes back to 09:03, 5 min after the stirring"):
        read_sheet(sheet, stirred="09:00")
    with pytest.raises(SheetError, match="say when the suspension was stirred with --stirred HH:MM"):
        read_sheet(sheet)
    sheet.write_text("clock,reading,temperature_C\n9:61,30,22\n")
    with pytest.raises(SheetError, match="line 2: '9:61' is not a clock time"):
        read_sheet(sheet, stirred="09:00")
    # a laboratory's 12-hour clock (Penn State's 2022 sheets), stirred 9:17 AM, read into the next morning
    sheet.write_text("clock,reading,temperature_C\n9:19 AM,30,22\n12:05 PM,28,22\n7:16 PM,27,22\n10:30 AM,25,22\n")
    assert read_sheet(sheet, stirred="9:17 AM").time / 60 == pytest.approx([2, 168, 599, 1513])
    sheet.write_text("clock,reading,temperature_C\n13:19 PM,30,22\n")
    with pytest.raises(SheetError, match="'13:19 PM' is not a clock time: HH:MM on 24 hours"):
        read_sheet(sheet, stirred="1:00 PM")


def _refusal(capsys, argv) -> str:
    assert main(argv) == 2
    return capsys.readouterr().err


def test_what_a_laboratory_may_give_wrongly_is_refused_with_the_fix(tmp_path, capsys):
    sheets = [str(SAMPLES[0] / "hydrometer.csv")]
    out = ["--out", str(tmp_path / "out")]
    assert "give the oven-dry mass, or the air-dry mass" in _refusal(
        capsys, ["invert", *sheets, "--mass", "0.025", "--air-dry-mass", "0.026", "--water-content", "0.035", *out])
    assert "--air-dry-mass needs --water-content" in _refusal(capsys, ["invert", *sheets, "--air-dry-mass", "0.026", *out])
    assert "--volume and --height" in _refusal(
        capsys, ["invert", *sheets, "--mass", "0.025", "--volume", "1e-3", "--height", "0.36", *out])
    assert "--washed needs the sieve sheet" in _refusal(capsys, ["invert", *sheets, "--mass", "0.025", "--washed",
                                                                 "0.053", *out])
    # the overnight rise of a sheet with one blank: named by its line and the value on the sheet, with the option
    # that states a laboratory's own reading error
    risen = tmp_path / "risen.csv"
    text = (SAMPLES[0] / "hydrometer.csv").read_text().replace("598.0,14.0,22.0,7.0", "598.0,15.75,22.0,7.0")
    risen.write_text(text)
    message = _refusal(capsys, ["invert", str(risen), "--mass", "0.025", *out])
    assert "line 8, 598 min: the reading (15.75 on the sheet, 8.75 after its correction)" in message
    assert "reading before it (363 min: 14.75 on the sheet, 7.75 after its correction)" in message
    assert "--hydrometer-noise (now 0.25 g/L" in message
    assert not (tmp_path / "out").exists()


def test_a_two_reading_protocol_fits_without_a_false_alarm_and_its_lab_apparatus_is_echoed(tmp_path, capsys):
    """The 4 h / 21 h protocol: two readings whose cuts lie a decade below the 53 um sieve; the silt
    between rises by about 25 points there, which is no step to check."""
    sample = SAMPLES[3]
    rows = (sample / "hydrometer.csv").read_text().splitlines()
    two = tmp_path / "hydrometer.csv"
    two.write_text("\n".join([rows[0], rows[6], rows[8]]) + "\n")
    options = json.loads((sample / "sample.json").read_text())
    code = main(["invert", str(two), str(sample / "sieve.csv"), *LAB, "--air-dry-mass", str(options["air-dry-mass"]),
                 "--water-content", str(options["water-content"]), "--cylinder-area", str(options["cylinder-area"]),
                 "--particles", "4000", "--out", str(tmp_path / "out")])
    printed = capsys.readouterr().out
    assert code == 0, printed
    assert "check: the curve rises" not in printed
    assert "suspension 1000 mL in a cylinder of 26.4 cm2" in printed
    assert "hydrometer 152H: calibrated: H_r 20.3 cm at -5 g/L, 8.6 cm at 60 g/L; bulb 55 mL, 13.7 cm" in printed
    assert "unknown" not in (tmp_path / "out" / "texture.csv").read_text()
    summary = json.loads((tmp_path / "out" / "invert.json").read_text())
    assert summary["inputs"]["mass"] == pytest.approx(options["air-dry-mass"] / (1 + options["water-content"]))
    assert summary["inputs"]["hydrometer"]["calibration"] == [[-5.0, 0.203], [60.0, 0.086]]


def _sample_options(sample: Path) -> list[str]:
    """A sample's sample.json as the options of `sediment invert` (as the batch passes them)."""
    options = json.loads((sample / "sample.json").read_text())
    sheets = [str(sample / name) for name in options.pop("sheets")]
    return sheets + [word for name, value in options.items() for word in (f"--{name}", str(value))]


def test_a_sheet_as_kept_with_gravel_in_its_sieves_fits_and_says_what_its_class_is_of(tmp_path, capsys):
    """Penn State's 2022 sheet of a sandy loam with 14.6 % gravel: a 12-hour clock read into the next day,
    sieves to 6.73 mm. The USDA class is of the fine earth, its fractions sum to 100; ISO's gravel is the
    sieves' 100 - P(2 mm); the console says how USDA names a gravel modifier."""
    sample = REAL / "p24_ryan_shaffer_r1"
    code = main(["invert", *_sample_options(sample), *LAB, "--particles", "4000", "--out", str(tmp_path / "out")])
    printed = capsys.readouterr().out
    assert code == 0, printed
    report = json.loads((tmp_path / "out" / "invert.json").read_text())["texture"]
    usda = report["fractions"]["USDA"]
    assert sum(usda[name]["percent"] for name in ("clay", "silt", "sand")) == pytest.approx(100.0)
    assert report["fractions"]["ISO 14688-1"]["gravel"]["percent"] == pytest.approx(100 - 85.38, abs=0.01)
    assert "14.6 % of the sample's mass is gravel, which USDA names by volume" in printed
    assert "check: the curve rises" not in printed and "unknown" not in (tmp_path / "out" / "texture.csv").read_text()


def test_a_batch_inverts_every_sample_names_the_broken_one_and_resumes(tmp_path, capsys):
    batch = tmp_path / "batch"
    for sample in SAMPLES[:2]:
        shutil.copytree(sample, batch / sample.name)
    (batch / "broken").mkdir()
    (batch / "broken" / "hydrometer.csv").write_text("time_min,reading,temperature_C\n")
    (batch / "broken" / "sample.json").write_text('{"mass": 0.025}')
    argv = ["invert", "--batch", str(batch), *LAB, "--particles", "4000", "--jobs", "2", "--out", str(tmp_path / "out")]
    assert main(argv) == 2
    captured = capsys.readouterr()
    assert "1 of 3 samples could not be inverted (broken)" in captured.err
    summary = (tmp_path / "out" / "summary.csv").read_text()
    assert "broken,error: sediment invert: error:" in summary and "no readings below the header" in summary
    for sample in SAMPLES[:2]:
        assert f"{sample.name},fits" in summary
        assert (tmp_path / "out" / sample.name / "psd.csv").exists()
    assert (tmp_path / "out" / "summary.png").exists()
    # again: the finished samples are not run again; one whose sheet changed is
    changed = batch / SAMPLES[1].name / "hydrometer.csv"
    changed.write_text(changed.read_text().replace(",22.0,", ",22.5,"))
    assert main(argv) == 2
    printed = capsys.readouterr().out
    assert f"{SAMPLES[0].name}: fits" in printed and "(done before with the same inputs)" in printed
    assert printed.count("(done before with the same inputs)") == 1


def test_one_misread_row_is_named_as_such_not_as_a_unit(tmp_path, capsys):
    """A 41 C among 19-21 C rows is a misreading of that row, not a sheet in Fahrenheit (41 F is 5 C); a
    sphere whose own mass is off makes every reading 'beyond the whole sample', and the message names it."""
    sheet = tmp_path / "h.csv"
    sheet.write_text("time_min,reading,temperature_C\n1,30,19\n2,28,41\n4,27,21\n")
    with pytest.raises(SheetError, match="line 3: temperature_C 41 C is not within 0-40 C: .*the column's other rows "
                                         "read 19 to 21 C: check this one \\(or written in F\\? that is 5 C"):
        read_sheet(sheet)
    sheet.write_text("time_min,reading,temperature_C\n1,30,68\n2,28,70\n")
    with pytest.raises(SheetError, match="written in F\\? that is 20 C"):
        read_sheet(sheet)
    buoyancy = REPO / "examples" / "inverse" / "buoyancy.csv"
    message = _refusal(capsys, ["invert", str(buoyancy), "--mass", "0.06", "--sphere-mass", "0.021",
                                "--out", str(tmp_path / "out")])
    assert "--sphere-mass, --sphere-diameter" in message
