#!/usr/bin/env bash
# cmake --install into a fresh prefix, then the installed pxf renders a built-in scene with its own
# copy of the scenes (it says where it reads them), and writes its outputs.
#   tests/install_test.sh BUILD_DIR
set -euo pipefail
build="$1"
prefix="$(mktemp -d)"
trap 'rm -rf "$prefix"' EXIT
cmake --install "$build" --prefix "$prefix" >/dev/null
"$prefix/bin/pxf" render --scene list | grep -qF "(in $prefix/share/pxf/assets)" ||
  { echo "the installed pxf does not read its scenes from $prefix/share/pxf/assets"; exit 1; }
for scene in cornell atrium kitchen envmap product window; do
  [ -f "$prefix/share/pxf/assets/$scene/$scene.gltf" ] || { echo "$scene was not installed"; exit 1; }
done
(cd "$prefix" && "$prefix/bin/pxf" render --scene kitchen --size 32x24 --spp 2 --quiet --out o >/dev/null)
[ -f "$prefix/o/final.png" ] || { echo "the installed pxf wrote no final.png"; exit 1; }
echo "installed pxf rendered kitchen from $prefix/share/pxf/assets"
