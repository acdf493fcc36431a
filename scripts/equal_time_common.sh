# Shared by scripts/equal_time_samplers.sh and scripts/equal_time_ab.sh (sourced, from the
# repository root): where a scene's reference is, and how a job is judged against it.
pxf=build/app/pxf

# The reference of SCENE in REFERENCE_DIR: <scene>/buffers.exr (a reference render's output) if
# there is one, else reference_<scene>_384x216_2048spp.exr (`pxf bench`'s cached reference).
# Exits with 2 when neither exists.
reference_of() {
  local refs=$1 scene=$2 ref="$1/reference_$2_384x216_2048spp.exr"
  [ -f "$refs/$scene/buffers.exr" ] && ref="$refs/$scene/buffers.exr"
  [ -f "$ref" ] || { echo "missing $ref (or $refs/$scene/buffers.exr)" >&2; exit 2; }
  echo "$ref"
}

# The spp a `pxf render --time` job reached (its OUT/stats.json).
spp_of() {
  python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['time_budget']['spp_reached'])" "$1/stats.json"
}

# "HDR DISPLAY" NRMSE from the line of `pxf diff TEST REFERENCE [ARGS...]` that starts with LABEL.
nrmse_pair() {
  local label=$1
  shift
  "$pxf" diff "$@" | grep "^$label" | sed -E 's/.*HDR NRMSE ([0-9.]+) %  display NRMSE ([0-9.]+).*/\1 \2/'
}

# "HDR DISPLAY" NRMSE of TEST against the reference of SCENE in REFERENCE_DIR. With SECOND_REFS=DIR
# (a second reference per scene, found the same way, rendered like the first with another seed),
# the noise-corrected error instead (`pxf diff --second-reference`): the reference's own noise
# taken out, which otherwise adds to every job's error alike and pulls every ratio toward 1.
judge() {
  local test=$1 refs=$2 scene=$3
  if [ -n "${SECOND_REFS:-}" ]; then
    nrmse_pair 'noise-corrected' "$test" "$(reference_of "$refs" "$scene")" \
      --second-reference "$(reference_of "$SECOND_REFS" "$scene")"
  else
    nrmse_pair 'all pixels' "$test" "$(reference_of "$refs" "$scene")"
  fi
}
