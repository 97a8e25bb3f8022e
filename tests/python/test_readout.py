# SPDX-License-Identifier: GPL-2.0-or-later
"""Readouts of the hydrometer, buoyancy sphere and pipette (docs/sedimentation-tests.md sections 3-5)."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from sediment.lab.psd import PSD, PSDError, discretise, read_psd
from sediment.lab.readout import SCHEDULES, BuoyancySphere, Column, Hydrometer, Pipette, R_FACTOR, Suspension
from sediment.lab.synthetic import settling_column

PSDS = Path(__file__).resolve().parents[2] / "examples" / "granulometry" / "psd"


def uniform(concentration: float, height: float = 0.36, suspension: Suspension = Suspension()) -> Column:
    phi = concentration / suspension.particle_density
    return Column(np.linspace(0, height, 361), np.array([0.0, 1.0]), np.full((2, 360), phi), suspension)


def test_152h_geometry_matches_d422():
    h = Hydrometer.astm_152h()
    assert np.sqrt(4 * h.stem_area / np.pi) == pytest.approx(5.7e-3, rel=0.01)     # stem about 5.7 mm
    assert h.mass == pytest.approx(69.6e-3, rel=0.002)                               # about 69.6 g
    # effective depth L = 16.3 - 0.1641 R cm (D422), with the level rise of VB / A_c. The marks are where
    # the instrument floats, which goes with 1 / rho: D422's table, linear in R, is 0.06 cm off mid-scale.
    column = uniform(30 * 2650 / (2650 - 998.2) * R_FACTOR)    # rho_s = rho_w + 0.6226 * 30
    reading = h.read(column, [0.5])
    assert reading.reading[0] == pytest.approx(30, abs=0.01)
    assert reading.depth[0] * 100 == pytest.approx(16.3 - 0.1641 * reading.reading[0], abs=0.07)


@pytest.mark.parametrize("grams_per_litre", [0, 5, 10, 20, 30, 40, 50, 60])
def test_hydrometer_reads_a_uniform_suspension(grams_per_litre):
    column = uniform(grams_per_litre)
    reading = Hydrometer.astm_152h().read(column, [0.5]).reading[0]
    assert reading == pytest.approx(grams_per_litre, abs=0.07)    # g/L of Gs 2.65 against water at 1000 kg/m3
    if grams_per_litre == 0:    # clear water: floats with the surface at the R = 0 mark
        assert Hydrometer.astm_152h().bulb_top_depth(column, 0.5) == pytest.approx(0.105, abs=1e-9)


def test_measured_instrument_is_a_parameter_set():
    nominal = Hydrometer.astm_152h()
    heavier = Hydrometer.measured(0.140, 67e-6, 5.72e-3, nominal.mass * 1.01, 0.105, 0.023)
    column = uniform(20)
    assert heavier.read(column, [0.5]).reading[0] < nominal.read(column, [0.5]).reading[0] - 5    # sinks deeper


def test_default_buoyancy_sphere_reads_what_a_balance_shows():
    """The 25 mm, 20 g Teflon sphere: 20 g less the liquid it displaces (8.18 cm3), so 11.8 g in water and
    0.31 g less in 60 g/L of 2650 kg/m3 solids (rho_s - rho_w = 60 (1 - rho_w / 2650) kg/m3)."""
    sphere = BuoyancySphere(depth=0.1)
    volume_cm3 = np.pi / 6 * 2.5 ** 3
    water = sphere.read(uniform(0.0), [0.5])
    loaded = sphere.read(uniform(60.0), [0.5])
    rho_w, rho_p = Suspension().fluid_density / 1000, Suspension().particle_density / 1000    # g/cm3
    assert water.reading[0] == pytest.approx(20 - rho_w * volume_cm3, abs=1e-9)
    assert water.reading[0] - loaded.reading[0] == pytest.approx(60e-3 * (1 - rho_w / rho_p) * volume_cm3, rel=1e-9)
    # 100 % within the formula's Gs / (Gs - 1), Gs = rho_s / 1000, against water at 998.2: 0.11 % high
    assert loaded.percent_finer[0] == pytest.approx(100 * (1 - rho_w / rho_p) / (1 - 1 / rho_p), rel=1e-9)


def recovered_error(readings, psd: PSD, lo: float, hi: float) -> float:
    resolved = (readings.diameter >= lo) & (readings.diameter <= hi)
    assert resolved.sum() >= 3
    return float(np.max(np.abs(readings.percent_finer[resolved] - psd.at(readings.diameter[resolved]))))


@pytest.fixture(scope="module")
def sample5():
    psd = read_psd(PSDS / "sample5.csv")
    times = np.array(sorted(set(SCHEDULES["d422"] + SCHEDULES["d7928"] + SCHEDULES["bravo"]))) * 60.0
    suspension = Suspension(particle_density=2650.0)
    column = settling_column(psd, 0.36, np.concatenate([[0.0], times]), 50.0, suspension)
    return psd, column, times


INSTRUMENTS = {
    "hydrometer": lambda: Hydrometer.astm_152h(),
    "buoyancy": lambda: BuoyancySphere(depth=0.3 * 0.36),    # Bravo et al.: 0.3 H
    "pipette": lambda: Pipette(depth=0.10),                  # soil labs: 10 cm
}


@pytest.mark.parametrize("instrument", INSTRUMENTS)
def test_instrument_recovers_a_stokes_psd(sample5, instrument):
    """Sample 5 (smooth gradation) settling by Stokes' law alone: every reading between 3 and 60 um
    must sit within 2 percentage points of the PSD (the hydrometer's bulb averages over 14 cm)."""
    psd, column, times = sample5
    readings = INSTRUMENTS[instrument]().read(column, times)
    error = recovered_error(readings, psd, 3e-6, 60e-6)
    print(f"{instrument}: max |P - PSD| = {error:.3f} percentage points over 3-60 um")
    assert error < 2.0


def test_psd_validation(tmp_path):
    def table(text):
        path = tmp_path / "psd.csv"
        path.write_text(text)
        return path
    for text, message in [("", "empty PSD file"),
                          ("diameter_um,percent_finer\n", "no rows"),
                          ("size,pct\n10,0\n20,100\n", "header must be"),
                          ("diameter_um,percent_finer\n10,0\n10,50\n20,100\n", "diameters must increase: row 2"),
                          ("diameter_um,percent_finer\n10,0\n20,120\n", "within 0..100: row 2"),
                          ("diameter_um,percent_finer\n10,0\n20,60\n30,40\n", "must not decrease"),
                          ("diameter_um,percent_finer\n10,0\n20,abc\n", "two numbers"),
                          ("diameter_um,percent_finer\n10,0\n20,0.4\n70,1\n", "not fractions"),
                          ("diameter_um,percent_finer\n0.075,0\n0.6,40\n2,100\n", "millimetres"),
                          ("diameter_um,percent_finer\n2,5,0\n20,100\n", "line 2: 3 values where the header has 2 columns"),
                          ("diameter_um,percent_finer,note\n10,0,a\n20,100,b\n", "two columns")]:
        with pytest.raises(PSDError, match=message):
            read_psd(table(text))
    assert read_psd(table("\ufeffdiameter_um,percent_finer\n10,0\n20,100\n")).diameter[1] == pytest.approx(2e-5)
    with pytest.raises(PSDError, match="is a folder"):
        read_psd(tmp_path)
    binary = tmp_path / "psd.xlsx"
    binary.write_bytes(b"PK\x03\x04\xff\xfe\x00binary")
    with pytest.raises(PSDError, match="not a text"):
        read_psd(binary)


def test_discretisation_keeps_every_class_and_reports_the_simulated_psd():
    psd = read_psd(PSDS / "sample1.csv")    # 60 % fines, a plateau, 40 % coarse
    classes = discretise(psd, 60, sample_mass=0.06, particle_density=2500, volume_fraction=1e-7)
    assert np.all(classes.count[classes.mass_fraction > 0] >= 1)
    assert classes.mass_fraction.sum() == pytest.approx(1.0)
    simulated = classes.simulated_psd()
    assert simulated.percent_finer[-1] == pytest.approx(100.0)
    # where classes hold many particles the simulated PSD follows the input
    assert abs(simulated.at(15e-6) - psd.at(15e-6)) < 5


def test_column_from_a_layer_file_reads_depth_from_the_surface(tmp_path):
    from types import SimpleNamespace
    total = np.array([[0.1, 0.2, 0.3, 0.4]])    # layers from z = 0 up
    layers = SimpleNamespace(path=tmp_path / "x.h5", layer_lo=0.0, layer_thickness=0.1, centres=np.arange(4),
                             time=np.array([0.0]), total=total,
                             attributes={"fluid_density": 1000.0, "fluid_viscosity": 1e-3, "particle_density": 2650.0})
    column = Column.from_layers(layers, surface=0.35)
    assert np.allclose(column.depth_edges, [0.0, 0.05, 0.15, 0.25, 0.35])
    assert np.allclose(column.fraction[0], [0.4, 0.3, 0.2, 0.1])
    layers.attributes = {}
    with pytest.raises(ValueError, match="readouts need fluid_density"):
        Column.from_layers(layers)


def test_pipette_in_a_slab_samples_the_circle_of_its_sphere():
    """In the 2d slab (the cylinder's axial section) the 25 mL sample is the section of its sphere:
    a circle of the sphere's radius, whose chords weight the layers."""
    edges = np.linspace(0.0, 0.36, 36001)
    radius = (3 * 25e-6 / (4 * np.pi)) ** (1 / 3)
    step = 0.10 + 0.5 * radius                  # suspension above, clear water below
    fraction = np.where(edges[:-1] < step, 0.02, 0.0)
    column = Column(edges, np.array([0.0, 1.0]), np.vstack([np.full(36000, 0.02), fraction]), Suspension(),
                    slab_thickness=7e-5)
    reading = Pipette(0.10).read(column, [1.0])
    u = np.linspace(-radius, radius, 200001)     # chord weights, by direct summation
    above = np.sum(np.sqrt(radius ** 2 - u ** 2) * (0.10 + u < step)) / np.sum(np.sqrt(radius ** 2 - u ** 2))
    assert reading.percent_finer[0] == pytest.approx(100 * above, abs=0.05)
    assert 78 < reading.percent_finer[0] < 83    # 1 - (segment beyond r/2) / (pi r^2) = 80.4 %


@pytest.mark.parametrize("surface, gradient", [(10, 50), (0, 100), (30, -50), (5, 150)])
def test_a_floating_152h_reads_the_liquid_it_displaces(surface, gradient):
    """Hydrostatics, derived apart from the model's root finding: in a column whose solids rise linearly
    with depth, c = surface + gradient z [g/L, m], the 152H reads c at the mean depth from which the liquid
    beside its immersed stem and bulb came (inserted, it lifts the suspension at each level by its
    volume below it, over the cylinder's area). D7928's H_m is that depth for the bulb alone: the stem's
    2 cm3 in the thinner suspension above put the reading 0.34-0.43 cm shallower than H_m."""
    from sediment.constants import D422_CYLINDER_AREA as area

    water = Suspension.at_temperature(20.0)
    h = Hydrometer.astm_152h()
    edges = np.linspace(0.0, 0.36, 3601)
    depth = 0.5 * (edges[1:] + edges[:-1])
    solids = surface + gradient * depth
    column = Column(edges, np.array([0.0, 1.0]), np.vstack([solids, solids]) / 2650.0, water)
    top = h.bulb_top_depth(column, 0.5, area)
    stem, bulb = h.stem_area * top, h.bulb_volume
    stem_origin = top / 2 * (1 - h.stem_area / area)
    bulb_origin = top + h.bulb_length / 2 - (h.stem_area * top + bulb / 2) / area
    origin = (stem * stem_origin + bulb * bulb_origin) / (stem + bulb)
    reading = h.read(column, [0.5], area).reading[0]
    solids_read = (h.liquid_density(reading) - water.fluid_density) / (1 - water.fluid_density / 2650.0)
    assert solids_read == pytest.approx(surface + gradient * origin, abs=1e-6)
    assert 0.0034 < h.effective_depth(reading, area) - origin < 0.0044
