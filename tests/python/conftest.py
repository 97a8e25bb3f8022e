# SPDX-License-Identifier: GPL-2.0-or-later
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(REPO / "python"))
os.environ.setdefault("SEDIMENT_LMP", str(REPO / "build" / "lmp_sediment"))
