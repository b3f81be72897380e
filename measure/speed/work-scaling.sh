#!/usr/bin/env bash
# Does a render's time fall with its work? For a shipped scene, times the render at
# its own settings against the same render with half the camera samples, half the
# light samples, and half the pixels, alternating each pair (full, half, full,
# half, ...) and printing the median of the per-pair ratios with their range.
#
#   measure/speed/work-scaling.sh                       # cornell-set1, 5 pairs
#   measure/speed/work-scaling.sh scenes/bunny-cornell.toml 3
#
# Times are Glint's own "rendering" figure (parse, load and write excluded).
# Builds the release binary first. Prints a Markdown table.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$repo"

scene="${1:-scenes/cornell-set1.toml}"
pairs="${2:-5}"
[[ -f "$scene" ]] || { echo "work-scaling.sh: error: no scene file $scene" >&2; exit 2; }
[[ "$pairs" =~ ^[1-9][0-9]*$ ]] || { echo "work-scaling.sh: error: pairs must be a positive integer, got $pairs" >&2; exit 2; }

cargo build --release --quiet -p glint-cli
glint="$repo/target/release/glint"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# The scene's own settings, from a one-sample probe render's summary line.
if ! probe="$("$glint" render "$scene" --spp 1 -o "$out/probe.png" 2>&1)"; then
    echo "work-scaling.sh: error: $scene does not render: $(tail -n 1 <<<"$probe")" >&2
    exit 2
fi
probe="$(tail -n 1 <<<"$probe")"
read -r width height < <(sed -E 's/.*: ([0-9]+)x([0-9]+),.*/\1 \2/' <<<"$probe")
spp="$(sed -nE 's/^spp *= *([0-9]+).*/\1/p' "$scene" | head -n 1)"
light="$(sed -nE 's/^light_samples *= *([0-9]+).*/\1/p' "$scene" | head -n 1)"
spp="${spp:-16}"; light="${light:-16}"

# Render seconds of one run with extra flags.
render_seconds() {
    "$glint" render "$scene" -o "$out/image.png" "$@" 2>&1 | tail -n 1 \
        | sed -nE 's/.*\(([0-9.]+) s rendering\).*/\1/p'
}

# Median and range of half/full over alternated pairs.
ratio() {
    local ratios=()
    for _ in $(seq "$pairs"); do
        local full half
        full="$(render_seconds)"
        half="$(render_seconds "$@")"
        ratios+=("$(python3 -c "print($half / $full)")")
    done
    python3 - "${ratios[@]}" <<'PY'
import statistics, sys
r = sorted(float(x) for x in sys.argv[1:])
print(f"{statistics.median(r):.2f} ({r[0]:.2f}–{r[-1]:.2f})")
PY
}

half_w=$(( width * 707 / 1000 )); half_h=$(( height * 707 / 1000 ))
echo "$scene at ${width}x${height}, $spp spp, $light light samples; $pairs alternated pairs"
echo
echo "| half the work | time / full time (median, range) |"
echo "|---|---|"
echo "| $(( spp / 2 )) spp instead of $spp | $(ratio --spp $(( spp / 2 ))) |"
echo "| $(( light / 2 )) light samples instead of $light | $(ratio --light-samples $(( light / 2 ))) |"
echo "| ${half_w}x${half_h} instead of ${width}x${height} (half the pixels) | $(ratio --resolution "${half_w}x${half_h}") |"
