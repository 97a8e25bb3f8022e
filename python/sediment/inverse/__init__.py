# SPDX-License-Identifier: GPL-2.0-or-later
"""From a laboratory's sheets to the sample's PSD (docs/inverse.md).

The readings of a test are nearly linear in the mass of each size class: classes settle on their own
but for the hindrance, which the whole suspension sets. So:

1. The sheets' standard reduction and the sieves give a first PSD.
2. Each reading cuts the sample at one diameter (`model.cut_diameters`: the grains the forward model's
   hindered drag carries past the instrument's depth by the reading's time); the bins' edges
   (`grid.size_grid`) are those cuts, the sieves' openings, the texture classes' limits and, above the
   coarsest cut and below the finest, the tails, whose placement no reading says.
3. One DEM run of the test with that PSD, sand to the specimen's largest grain included, writes each
   bin's layer fractions; scaling them gives the column of any other split of the mass
   (`model.ForwardRun`), as that run's hindrance left it.
4. The instruments read those columns at the sheet's times, linearised in the bins' masses; with the
   sieves' percent passing (linear already), a constrained least squares (`fit.fit`) finds the masses.
5. Rounds of runs update the hindrance; draws of the data's noise and the priors give the band.

`sediment.lab` keeps what needs no simulation (instruments, sheets, PSDs, texture); this package runs
the simulator, so it sits above `sediment.sim` and `sediment.planner`.
"""
from .design import DESIGNS, clay_reading_time, design_test
from .grid import SizeGrid, size_grid
from .invert import Inversion, invert
from .model import LabTest, effective_times, whole_sample_reading

__all__ = ["DESIGNS", "Inversion", "LabTest", "SizeGrid", "clay_reading_time", "design_test", "effective_times",
           "invert", "size_grid", "whole_sample_reading"]
