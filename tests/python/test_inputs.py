# SPDX-License-Identifier: GPL-2.0-or-later
"""What every command takes in (docs/inputs.md): options and file values outside their plausible range
refused with the unit slip that explains them, and the CSVs a spreadsheet exports read where they are
unambiguous and refused in one line naming the file and the line where they are not."""
from __future__ import annotations

import argparse
import glob
from pathlib import Path

import pytest

from sediment import cli
from sediment.csvfile import CsvError, read_csv
from sediment.lab.psd import read_psd
from sediment.lab.sheet import SheetError, read_sheet, read_temperature_record
from sediment.plausible import RANGES
from sediment.studies.valentik import read_spheres

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "inverse"
PSD = str(REPO / "examples" / "granulometry" / "psd" / "sample5.csv")
HYDROMETER = "time_min,reading,temperature_C\n1,45,20\n2,40,20\n"


def _refusal(capsys, argv: list[str]) -> str:
    """The one error line of a command refused (argparse's or the command's), exit status 2."""
    try:
        code = cli.main(argv)
    except SystemExit as exit_:    # argparse refuses a value of a type
        code = exit_.code
    err = capsys.readouterr().err
    assert code == 2, err
    return err.strip().splitlines()[-1]


@pytest.mark.parametrize("argv, slip", [
    (["invert", "h.csv", "--mass", "0.06", "--pipette-volume", "0.025"], "written in L? that is 2.5e-05 m3"),
    (["invert", "h.csv", "--mass", "0.06", "--pipette-volume", "25"], "written in mL? that is 2.5e-05 m3"),
    (["invert", "h.csv", "--mass", "0.06", "--particle-density", "2.65"], "written in g/cm3? that is 2650 kg/m3"),
    (["invert", "h.csv", "--mass", "0.06", "--particle-density", "1000"], "grains settle in water only if denser"),
    (["invert", "h.csv", "--mass", "0.06", "--particle-density", "900"], "grains settle in water only if denser"),
    (["invert", "h.csv", "--mass", "0.06", "--sphere-mass", "20"], "written in g? that is 0.02 kg"),
    (["invert", "h.csv", "--mass", "0.06", "--sphere-mass", "0.2"], "would be 2.445e+04 kg/m3, denser than any solid"),
    (["invert", "h.csv", "--mass", "0.06", "--sphere-diameter", "25"], "written in mm? that is 0.025 m"),
    (["invert", "h.csv", "--mass", "60"], "written in g? that is 0.06 kg"),
    (["invert", "h.csv", "--mass", "0.6"], "0.6 kg is not within 0.01-0.2 kg"),
    (["invert", "h.csv", "--mass", "0.06", "--split", "2000"], "written in um? that is 2 mm"),
    (["invert", "h.csv", "--mass", "0.06", "--cylinder-area", "27.8"], "written in cm2? that is 0.00278 m2"),
    (["invert", "h.csv", "--mass", "0.06", "--height", "36"], "written in cm? that is 0.36 m"),
    (["invert", "h.csv", "--mass", "0.06", "--cylinder-area", "0.0278", "--height", "0.36"],
     "--cylinder-area 0.0278 m2 x height 0.36 m: 10.008 L is not within 0.2-5 L"),
    (["invert", "h.csv", "--mass", "0.06", "--cylinder-area", "0.0278"],
     "--cylinder-area 0.0278 m2 makes the 1 L suspension's height 0.0359712 m is not within 0.05-2 m"),
    (["invert", "h.csv", "--mass", "0.06", "--volume", "1000"], "written in mL? that is 0.001 m3"),
    (["invert", "h.csv", "--air-dry-mass", "0.06", "--water-content", "15"], "written in percent? that is 0.15"),
    (["sample", PSD, "--mass", "60"], "written in g? that is 0.06 kg"),
    (["sample", PSD, "--t-end", "24"], "written in h? that is 86400 s"),
    (["sample", PSD, "--temperature", "68"], "written in F? that is 20 C"),
    (["readout", "--psd", PSD, "--stokes-preview", "--temperature", "293"], "written in K? that is 19.85 C"),
    (["budget", PSD, "--mass", "60"], "written in g? that is 0.06 kg"),
    (["readout", "--psd", PSD, "--stokes-preview", "--viscosity", "1"], "written in mPa s (cP)? that is 0.001 Pa s"),
    (["readout", "--psd", PSD, "--stokes-preview", "--concentration", "0.05"], "that is 50 g/L"),
    (["readout", "--psd", PSD, "--stokes-preview", "--pipette-depth", "10"], "written in cm? that is 0.1 m"),
    (["readout", "--psd", PSD, "--stokes-preview", "--hydrometer", "0.14", "67", "0.006", "0.07", "0.105", "0.023"],
     "--hydrometer VB 67 m3 is not within 1e-05-0.0003 m3: a hydrometer's bulb (152H: 67 cm3); written in cm3 (mL)?"),
    (["terminal", "--diameter", "50", "--particle-density", "2650"], "written in um? that is 5e-05 m"),
    (["terminal", "--diameter", "5e-5", "--particle-density", "2650", "--fluid-density", "1.0"], "that is 1000 kg/m3"),
    (["terminal", "--diameter", "5e-5", "--particle-density", "2650", "--youngs-modulus", "200"], "written in GPa?"),
    (["terminal", "--diameter", "5e-5", "--particle-density", "2650", "--poisson-ratio", "30"], "that is 0.3"),
    (["terminal", "--diameter", "5e-5", "--particle-density", "2650", "--gravity", "981"], "that is 9.81 m/s2"),
    (["terminal", "--diameter", "5e-5", "--particle-density", "2650", "--solid-fraction", "20"], "that is 0.2"),
    (["paste", "energy", "--fall", "255"], "written in mm? that is 0.255 m"),
    (["paste", "restitution", "--target", "61.2"], "written in percent? that is 0.612"),
    (["calibrate", "slump", "--slump", "102", "--height", "0.152", "--density", "1843"], "that is 0.102 m"),
    (["calibrate", "slump", "--slump", "0.1", "--height", "0.152", "--density", "1.843"], "that is 1843 kg/m3"),
    (["sweep", "in.deck", "--dt", "1", "--observe", "x", "--tolerance", "1"], "written in percent? that is 0.01"),
    (["plan", PSD, "--measure-contacts", "--contact-cut", "5e-5"], "written in m? that is 50 um"),
    (["plan", PSD, "--tolerance", "50", "--screen-only"], "--tolerance 50 points is not within 0.01-20 points"),
])
def test_a_unit_slip_is_named_with_the_value_meant(tmp_path, capsys, argv, slip):
    (tmp_path / "h.csv").write_text(HYDROMETER)
    argv = [str(tmp_path / a) if a == "h.csv" else a for a in argv]
    assert slip in _refusal(capsys, [*argv, "--out", str(tmp_path / "out")] if argv[0] != "terminal" else argv)
    assert not (tmp_path / "out" / "psd.csv").exists()


def _parsers() -> list[argparse.ArgumentParser]:
    """Every command's parser and sub-parser."""
    found, stack = [], [cli.build_parser()]
    while stack:
        parser = stack.pop()
        found.append(parser)
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                stack.extend(action.choices.values())
    return found


def test_every_default_is_within_its_range():
    checked = 0
    for parser in _parsers():
        for action in parser._actions:
            name = getattr(action.type, "__name__", "")
            if name in RANGES and action.default is not None:
                for value in action.default if isinstance(action.default, list) else [action.default]:
                    assert RANGES[name].refusal(value) is None, (parser.prog, action.dest, value)
                    checked += 1
    assert checked > 30


def test_every_example_file_is_read():
    for name in glob.glob(str(REPO / "examples" / "**" / "*.csv"), recursive=True) + \
            glob.glob(str(REPO / "tests" / "data" / "*.csv")):
        if Path(name).name.startswith("reference_"):
            continue    # a laboratory's own results beside its sheets (examples/inverse/real-lab), read by their tests
        header = read_csv(name).header
        if "diameter_um" in header:
            read_psd(name)
        elif "rho_f" in header:
            read_spheres(name)
        elif "time_min" in header or "opening_mm" in header:
            read_sheet(name)
            if "temperature_C" in header:
                read_temperature_record(name)


@pytest.mark.parametrize("data", [
    ("\ufeff" + HYDROMETER).encode(),                                      # Excel's CSV UTF-8
    HYDROMETER.encode("utf-16"),                                           # Excel's Unicode text, its mark first
    b"\xfe\xff" + HYDROMETER.encode("utf-16-be"),
    HYDROMETER.replace("\n", ",\n").encode(),                              # a trailing empty column
    "time_min,reading,temperature_C\n1,45,20,\n2,40,20,,\n".encode(),      # empty cells past the header
    HYDROMETER.replace("\n", "\r\n").encode(),
    ("# 152H, cylinder 3\n\n" + HYDROMETER + "\n,,\n").encode(),                # comments, blank and empty rows
])
def test_what_a_spreadsheet_writes_is_read_where_it_is_unambiguous(tmp_path, data):
    path = tmp_path / "sheet.csv"
    path.write_bytes(data)
    sheet = read_sheet(path)
    assert list(sheet.reading) == [45.0, 40.0] and list(sheet.temperature) == [20.0, 20.0]


@pytest.mark.parametrize("data, message", [
    (HYDROMETER.replace(",", ";").encode(), "sheet.csv, line 1: the columns are separated by ';'"),
    (HYDROMETER.replace(",", "\t").encode(), "sheet.csv, line 1: the columns are separated by tabs"),
    ("time_min,reading,temperature_C\n1,45,20\n2,40,5,20\n".encode(),
     "sheet.csv, line 3: 4 values where the header has 3 columns (time_min,reading,temperature_C): a decimal comma"),
    ('time_min,reading,temperature_C\n1,45,20\n2,"40,5",20\n'.encode(),
     "sheet.csv, line 3: reading '40,5' is not a number: a decimal comma? write 40.5"),
    (("# température de l'eau\n" + HYDROMETER).encode("latin-1"),
     "sheet.csv, line 1: byte 0xe9 is not UTF-8 text ('é' in Latin-1/Windows-1252)"),
    (HYDROMETER.encode("utf-16-le"), "UTF-16 without its byte-order mark"),
    ("time_min,reading,temperature_C,reading\n1,45,20,44\n".encode(),
     "sheet.csv, line 1: column reading appears twice (columns 2 and 4)"),
    (HYDROMETER.replace("reading", "read\u200bing").encode(), "U+200B ZERO WIDTH SPACE: retype the header"),
    (HYDROMETER.replace("45", "4\u00a05").encode(), "line 2: reading '4\u00a05' is not a number: it holds an invisible "
                                                    "character, U+00A0 NO-BREAK SPACE"),
    ("time_min,,temperature_C\n1,45,20\n".encode(), "line 1: column 2 has no name"),
    ("time_min,reading,temperature_C\n1,45\n2,40,20\n".encode(), "sheet.csv, line 2: 2 values where the header has 3"),
    ("time_min,reading,temperature_C\n1,45,20\n2,nan,20\n".encode(), "line 3: reading is nan, not a finite number"),
    (b"", "empty sheet"),
    ((HYDROMETER + HYDROMETER).encode(), "sheet.csv, line 4: the header again (two tables in one file?)"),
])
def test_what_cannot_be_read_is_refused_in_one_line_naming_the_file_and_line(tmp_path, data, message):
    path = tmp_path / "sheet.csv"
    path.write_bytes(data)
    with pytest.raises(SheetError) as refused:
        read_sheet(path)
    assert message in str(refused.value) and "\n" not in str(refused.value)


@pytest.mark.parametrize("rows, message", [
    ("1,45,20\n2,40,20\n86400,5,20\n", "line 4: time_min 86400 min is not within 0.05-10080 min: a sedimentation test "
                                       "is read from seconds after the start to a week; the column's other rows read 1 "
                                       "to 2 min: check this one (or written in s? that is 1440 min"),
    ("1,45,68\n2,40,68\n", "line 2: temperature_C 68 C is not within 0-40 C: the water correlations' range; written in "
                           "F? that is 20 C: give 20"),
    ("1,45,20\n2,450,20\n", "line 3: reading 450 g/L is not within -5 to 60 g/L: a 152H's scale runs from -5 to 60 g/L"),
])
def test_a_sheet_value_out_of_range_names_its_line_and_slip(tmp_path, rows, message):
    path = tmp_path / "sheet.csv"
    path.write_text("time_min,reading,temperature_C\n" + rows)
    with pytest.raises(SheetError, match="sheet.csv, " + message.replace("?", r"\?").replace("(", r"\(")
                       .replace(")", r"\)")):
        read_sheet(path)


@pytest.mark.parametrize("text, message", [
    ("time_min,depth_cm,mass_g\n1,0.1,1.2\n", "line 2: depth_cm 0.1 cm is not within 1-200 cm"),
    ("time_min,depth_cm,mass_g\n1,10,1200\n", "line 2: mass_g 1200 g is not within 0-7.5 g: the solids of a 25 mL "
                                              "sample of at most 300 g/L; written in mg? that is 1.2 g"),
    ("time_min,apparent_mass_g\n1,0.0115\n", "written in kg? that is 11.5 g"),
    ("time_min,apparent_mass_g\n1,11500\n", "written in mg? that is 11.5 g"),
])
def test_pipette_and_sphere_sheets_name_their_slips(tmp_path, text, message):
    path = tmp_path / "sheet.csv"
    path.write_text(text)
    with pytest.raises(SheetError) as refused:
        read_sheet(path)
    assert message in str(refused.value)


def test_every_csv_input_goes_through_one_reader(tmp_path):
    """PSD tables, temperature records and the spheres' CSV refuse alike what a sheet refuses."""
    bad = tmp_path / "bad.csv"
    bad.write_bytes("diameter_um;percent_finer\n2;0\n20;100\n".encode())
    for reader in (read_psd, read_temperature_record, read_spheres):
        with pytest.raises(ValueError, match="bad.csv, line 1: the columns are separated by ';'"):
            reader(bad)
    record = tmp_path / "record.csv"
    record.write_bytes(("time_min,temperature_C\n0,19\n600,68\n").encode("utf-16"))
    with pytest.raises(SheetError, match="line 3: temperature_C 68 C .* written in F"):
        read_temperature_record(record)
    psd = tmp_path / "psd.csv"
    psd.write_bytes(("\ufeffdiameter_um,percent_finer,\n2,0,\n20,100,\n").encode())
    assert list(read_psd(psd).percent_finer) == [0, 100]
    spheres = tmp_path / "spheres.csv"
    spheres.write_text("suspension,rho_f,eta_B,tau_y,d,rho_p,v_ter_measured\n1,1.28,0.0131,30.5,0.019,6513,0.65\n")
    with pytest.raises(ValueError, match="line 2: rho_f 1.28 kg/m3 .* written in g/cm3\\? that is 1280 kg/m3"):
        read_spheres(spheres)
    spheres.write_text("suspension,rho_f,eta_B,tau_y,d,rho_p,v_ter_measured\n1,1280,0.0131,30.5,19,6513,0.65\n")
    with pytest.raises(ValueError, match="line 2: d 19 m .* written in mm\\? that is 0.019 m"):
        read_spheres(spheres)
    with pytest.raises(CsvError, match="none.csv: no such file \\(the PSD file named\\)"):
        read_csv(tmp_path / "none.csv", "PSD file")


def test_the_same_sheet_twice_is_refused_however_it_was_saved(tmp_path, capsys):
    sheet = tmp_path / "h.csv"
    sheet.write_text(HYDROMETER)
    (tmp_path / "u16.csv").write_bytes(HYDROMETER.encode("utf-16"))    # the same readings saved as Unicode text
    line = _refusal(capsys, ["invert", str(sheet), str(tmp_path / "u16.csv"), "--mass", "0.06", "--out", str(tmp_path / "o")])
    assert f"{tmp_path / 'u16.csv'} and {sheet} hold the same readings" in line
    line = _refusal(capsys, ["invert", str(sheet), str(tmp_path / "." / "h.csv"), "--mass", "0.06", "--out", str(tmp_path / "o")])
    assert f"{sheet} is given twice" in line


def test_a_sheet_of_two_instruments_is_refused_naming_both(tmp_path):
    path = tmp_path / "both.csv"
    path.write_text("time_min,reading,temperature_C,apparent_mass_g\n1,45,20,11.5\n2,40,20,11.6\n")
    with pytest.raises(SheetError, match="the columns of hydrometer and buoyancy sheets: give each instrument"):
        read_sheet(path)


def test_the_docs_list_every_range_as_it_is():
    table = (REPO / "docs" / "inputs.md").read_text()
    for name, bounds in RANGES.items():
        span = f"{bounds.low:g} to {bounds.high:g}" if bounds.low < 0 else f"{bounds.low:g}-{bounds.high:g}"
        assert f"| {name} | {bounds.unit or '-'} | {span} |" in table, name
