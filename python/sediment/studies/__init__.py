# SPDX-License-Identifier: GPL-2.0-or-later
"""Studies that run decks and compare them with analytic solutions or measurements: the time-step
sweep, case A, Valentik & Whitmore's spheres, and the paste cases D-F. Each returns a result with
``table()`` and ``save(folder)``."""
