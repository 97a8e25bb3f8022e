# SPDX-License-Identifier: GPL-2.0-or-later
"""The instrument registry (sediment.lab.instruments): the command line's names are the table's, and an
unknown name is refused with the valid ones rather than read as another instrument."""
from __future__ import annotations

import numpy as np
import pytest

from sediment import constants
from sediment.inverse.model import whole_sample_reading, LabTest
from sediment.lab.granulometry import read_all
from sediment.lab.instruments import HYDROMETERS, INSTRUMENTS, Instrument, hydrometer, instrument
from sediment.lab.psd import PSD
from sediment.lab.readout import Suspension
from sediment.lab.sheet import KINDS, Sheet
from sediment.lab.synthetic import settling_column


def test_the_command_lines_names_are_the_registrys():
    assert tuple(INSTRUMENTS) == constants.INSTRUMENTS
    assert tuple(HYDROMETERS) == constants.HYDROMETER_TYPES
    assert INSTRUMENTS["hydrometer"] is HYDROMETERS[constants.HYDROMETER_TYPES[0]]    # the default type
    assert all(isinstance(i, Instrument) and i.name == name for name, i in INSTRUMENTS.items())
    # every instrument's sheet is a kind of sheet, told apart by its columns; sieves are a sheet of their own
    assert set(KINDS) == set(INSTRUMENTS) | {"sieve"}
    assert len({i.columns for i in INSTRUMENTS.values()}) == len(INSTRUMENTS)


def test_an_unknown_instrument_is_refused_with_the_valid_ones():
    with pytest.raises(ValueError, match="unknown instrument 'hydrometre': the instruments are hydrometer, buoyancy, "
                                         "pipette"):
        instrument("hydrometre")
    with pytest.raises(ValueError, match="unknown hydrometer type '152h': the types are 152H, 151H"):
        instrument("hydrometer", "152h")
    assert instrument("hydrometer", "151H") is hydrometer("151H") and hydrometer("151H").sheet_unit() == "specific gravity"
    psd = PSD(np.array([1e-6, 1e-5, 1e-4]), np.array([0.0, 50.0, 100.0]))
    column = settling_column(psd, 0.36, np.array([0.0, 60.0, 600.0]), 50.0, Suspension())
    with pytest.raises(ValueError, match="unknown instrument 'sphere'"):    # was read as the pipette
        read_all(column, ["hydrometer", "sphere"])
    sheet = Sheet("balance", None, np.array([60.0]), np.zeros(1), np.full(1, 20.0))
    with pytest.raises(ValueError, match="unknown instrument 'balance'"):    # was read as the buoyancy sphere
        whole_sample_reading(sheet, LabTest(0.06), Suspension())
