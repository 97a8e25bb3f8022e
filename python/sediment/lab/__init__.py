# SPDX-License-Identifier: GPL-2.0-or-later
"""The laboratory side: particle-size distributions, the instruments of sedimentation tests
(hydrometer, buoyancy sphere, pipette) and their readouts, and the calibration tests of pastes and
contacts. Nothing here runs LAMMPS."""
