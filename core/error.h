// pxf::Error: every user-facing failure (bad file, bad flag, bad scene, a GL context that cannot be
// made) is one of these, with a one-line message. The bottom layer: every library may throw it.
#pragma once
#include <stdexcept>

namespace pxf {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace pxf
