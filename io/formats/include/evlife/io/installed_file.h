// Files installed beside the evlife tool by `cmake --install` (the default
// configuration, the media plugin): found relative to the running executable,
// so that any prefix, a staged DESTDIR or a copied tree works.
#pragma once

#include <string>

namespace evlife::io {

/// The running executable's folder joined with `relative` (e.g.
/// "../share/evlife/evlife.yaml"; an absolute path is taken as it is),
/// normalised; empty when the executable's path cannot be read.
std::string beside_executable(const std::string& relative);

/// beside_executable(relative) when that file exists; else empty.
std::string installed_file(const std::string& relative);

}  // namespace evlife::io
