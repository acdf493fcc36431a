#!/bin/sh
# Writes the named state_reader seeds of fuzz/corpus/state_reader/ with the pxf given (default
# build/app/pxf). Run it after every state format version bump: a seed of another version stops at
# the version check and reaches nothing behind it. The seeds:
#   cornell_4x3, envmap_3x2   uniform renders (--spp 3, --spp 2; the envmap's holds its environment visibility)
#   shard_replicates          a shard (--frames 4:8) with --replicates 4: the replicate arrays
#   adaptive_6x4              an adaptive render past its warm-up (--spp 20): traced counts and the allocation
#   adaptive_merged           the merge of two adaptive shards 0:18 and 18:36, adjacent ranges kept apart
#   guided_4x3                a render with --guiding on (--spp 4): the serialized guiding field
#   split_4x3                 a render with --split-decision on (--spp 5): the even halves
#   truncated                 the first 400 bytes of cornell_4x3
#   frames_2pow31             a 2x1 --frames 0:2 state with its range end patched to 2^31 and the
#                             checksum recomputed (CountsAndLimits.AStateOf2To31FramesIsRefusedWithOneLine)
set -eu
PXF=$(realpath "${1:-build/app/pxf}")
SEEDS=$(dirname "$(realpath "$0")")/corpus/state_reader
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
cd "$TMP"
render() { out=$1; shift; "$PXF" render --quiet --out "$out" "$@" >/dev/null; }
render c --scene cornell --size 4x3 --spp 3 --checkpoint 100
render e --scene envmap --size 3x2 --spp 2 --checkpoint 100
render r --scene cornell --size 4x3 --frames 4:8 --replicates 4
render a --scene cornell --size 6x4 --spp 20 --adaptive on --checkpoint 100
render s0 --scene cornell --size 6x4 --frames 0:18 --adaptive on
render s1 --scene cornell --size 6x4 --frames 18:36 --adaptive on
"$PXF" merge s0/state.pxfs s1/state.pxfs --scene cornell --out m >/dev/null
render g --scene cornell --size 4x3 --spp 4 --guiding on --checkpoint 100
render h --scene cornell --size 4x3 --spp 5 --split-decision on --checkpoint 100
render f --scene cornell --size 2x1 --frames 0:2
cp c/state.pxfs "$SEEDS/cornell_4x3.pxfs"
cp e/state.pxfs "$SEEDS/envmap_3x2.pxfs"
cp r/state.pxfs "$SEEDS/shard_replicates.pxfs"
cp a/state.pxfs "$SEEDS/adaptive_6x4.pxfs"
cp m/state.pxfs "$SEEDS/adaptive_merged.pxfs"
cp g/state.pxfs "$SEEDS/guided_4x3.pxfs"
cp h/state.pxfs "$SEEDS/split_4x3.pxfs"
head -c 400 c/state.pxfs > "$SEEDS/truncated.pxfs"
python3 - f/state.pxfs "$SEEDS/frames_2pow31.pxfs" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], "rb").read()[:-8])
# After the magic (8), version (4) and settings (64 bytes at version 11), the range count (4), then
# the first range's begin and end.
settings_end = 8 + 4 + 64
assert struct.unpack_from("<I", data, settings_end)[0] == 1, "one frame range expected"
struct.pack_into("<I", data, settings_end + 8, 1 << 31)
h = 0xcbf29ce484222325
for b in data:
    h = ((h ^ b) * 0x100000001b3) & 0xFFFFFFFFFFFFFFFF
open(sys.argv[2], "wb").write(bytes(data) + struct.pack("<Q", h))
PY
echo "wrote the state seeds into $SEEDS"
