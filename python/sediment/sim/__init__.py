# SPDX-License-Identifier: GPL-2.0-or-later
"""The LAMMPS side: where the programs are, running decks, registering the styles in a Python
LAMMPS, writing the scene of a sedimentation test, and reading the layer files runs write."""
