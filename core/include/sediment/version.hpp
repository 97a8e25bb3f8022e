// SPDX-License-Identifier: GPL-2.0-or-later
// The release of SEDIMENT, stated here and nowhere else: CMakeLists.txt and setup.py read it from this
// line, the styles (the layer files' code_version) and the Python module (sediment.__version__, through
// sediment._core.VERSION) compile it in, and the documentation site imports it from there.
#pragma once

namespace sediment {

constexpr const char *version = "0.1.0";

}    // namespace sediment
