#!/usr/bin/python3
# SPDX-License-Identifier: GPL-2.0-or-later
"""Writes python/sediment/_core.pyi, the type stub of the compiled core, from the signatures pybind11
puts in its docstrings (tests/python/test_cli.py checks that the stub matches the built module):
    PYTHONPATH=python scripts/core-stub.py"""
from __future__ import annotations

import re
import sys
from pathlib import Path

STUB = Path(__file__).resolve().parents[1] / "python" / "sediment" / "_core.pyi"


def _types(signature: str) -> str:
    """pybind11's type names as a stub spells them."""
    signature = re.sub(r"numpy\.ndarray\[[^\]]*\]", "numpy.ndarray", signature)
    signature = signature.replace("sediment._core.", "").replace("List[", "list[").replace("Tuple[", "tuple[")
    return re.sub(r" = [^,)]+", " = ...", signature)    # defaults as ...: the docstring has their values


def _summary(doc: str) -> str:
    text = " ".join(doc.split("\n\n", 1)[1].split()) if "\n\n" in doc else ""
    return text.replace('"""', "'''")


def stub_text(core) -> str:
    """The stub of the module `core`."""
    lines = ['# SPDX-License-Identifier: GPL-2.0-or-later',
             '# Type stub of the compiled core: written by scripts/core-stub.py, do not edit.',
             '"""' + " ".join((core.__doc__ or "").split()) + '"""', "from __future__ import annotations", "",
             "import numpy", ""]
    for name in sorted(n for n in dir(core) if not n.startswith("_")):
        item = getattr(core, name)
        if isinstance(item, type):
            lines += ["", f"class {name}:", f'    """{" ".join((item.__doc__ or "").split())}"""']
            for method in ["__init__"] + sorted(m for m in vars(item) if not m.startswith("_")):
                doc = getattr(item, method).__doc__ or ""
                lines.append(f"    def {_types(doc.splitlines()[0])}: ...")
        elif not callable(item):    # a constant
            lines += ["", f"{name}: {type(item).__name__}"]
        else:
            doc = item.__doc__ or ""
            lines += ["", f"def {_types(doc.splitlines()[0])}:", f'    """{_summary(doc)}"""']
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    from sediment import _core

    STUB.write_text(stub_text(_core))
    print(f"wrote {STUB}")
    sys.exit(0)
