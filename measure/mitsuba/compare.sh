#!/usr/bin/env bash
# Glint's speed side by side with Mitsuba 3 on this machine: sets up a Python virtual
# environment with Mitsuba (once), builds Glint's release binary, and runs compare.py
# with the arguments given here (see measure/mitsuba/README.md, or pass --help).
#
#   measure/mitsuba/compare.sh                                  # every case, 5 pairs each
#   measure/mitsuba/compare.sh --case cornell-set1-random --pairs 3
#   measure/mitsuba/compare.sh --baseline /path/to/older/glint --json target/mitsuba/run.json
#   measure/mitsuba/compare.sh --equal-error                    # time to equal error (equal_error.py)
#
# Environment: GLINT_MITSUBA_VENV (default target/mitsuba-venv) is where the virtual
# environment lives; PYTHON (default python3) is the interpreter that creates it;
# DRJIT_LIBLLVM_PATH, if set, is the libLLVM Mitsuba's LLVM variants compile with.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
repo="$(cd "$here/../.." && pwd)"
cd "$repo"

die() { echo "compare.sh: error: $*" >&2; exit 2; }

venv="${GLINT_MITSUBA_VENV:-target/mitsuba-venv}"
python="${PYTHON:-python3}"

# Only --help: no venv, no build.
for arg in "$@"; do
    if [[ "$arg" == "-h" || "$arg" == "--help" ]]; then
        # All the arguments: --equal-error --help shows that mode's options.
        if [[ -x "$venv/bin/python" ]]; then exec "$venv/bin/python" "$here/compare.py" "$@"; fi
        exec "$python" "$here/compare.py" "$@"
    fi
done

# 1. The virtual environment with Mitsuba (which brings Dr.Jit; numpy is not needed).
if ! "$venv/bin/python" -c 'import mitsuba' >/dev/null 2>&1; then
    command -v "$python" >/dev/null || die "no $python to create the virtual environment with (set PYTHON)"
    "$python" -c 'import sys; sys.exit(sys.version_info < (3, 11))' \
        || die "$python is older than Python 3.11 (compare.py needs tomllib); set PYTHON"
    if [[ ! -x "$venv/bin/python" ]]; then
        echo "compare.sh: creating the virtual environment $venv" >&2
        "$python" -m venv "$venv" || die "could not create $venv (on Debian: apt-get install python3-venv)"
    fi
    echo "compare.sh: installing mitsuba into $venv" >&2
    "$venv/bin/python" -m pip install --quiet --upgrade pip >&2 || true
    "$venv/bin/python" -m pip install --quiet mitsuba >&2 || die "pip install mitsuba failed"
    "$venv/bin/python" -c 'import mitsuba' || die "mitsuba does not import in $venv after installing it"
fi

# 2. Mitsuba's LLVM variants (the default, llvm_ad_rgb) compile with the system's
# libLLVM, and LLVM 15 aborts on their kernels; compare.py picks the newest libLLVM
# and refuses one older than 17. Where there is none and apt-get can install one
# (Debian 12, as root), install it; otherwise compare.py says what to do.
variant=llvm_ad_rgb
prev=""
for arg in "$@"; do
    case "$arg" in
        --variant=*) variant="${arg#--variant=}" ;;
    esac
    if [[ "$prev" == "--variant" ]]; then variant="$arg"; fi
    prev="$arg"
done
if [[ "$variant" == llvm_* && -z "${DRJIT_LIBLLVM_PATH:-}" ]]; then
    newest=0
    for f in /usr/lib/*-linux-gnu/libLLVM*.so* /usr/lib64/libLLVM*.so* /usr/lib/llvm-*/lib/libLLVM*.so*; do
        [[ -e "$f" ]] || continue
        b="$(basename "$f")"
        if [[ "$b" =~ ^libLLVM-([0-9]+) || "$b" =~ ^libLLVM\.so\.([0-9]+) ]]; then
            (( BASH_REMATCH[1] > newest )) && newest="${BASH_REMATCH[1]}"
        fi
    done
    if (( newest < 17 )) && [[ "$(id -u)" == 0 ]] && command -v apt-get >/dev/null; then
        echo "compare.sh: Mitsuba's LLVM variants need libLLVM 17 or newer (newest found: ${newest/#0/none}); trying apt-get" >&2
        pick() { for p in libllvm19 libllvm18 libllvm17; do apt-cache show "$p" >/dev/null 2>&1 && { echo "$p"; return; }; done; }
        pkg="$(pick)"
        if [[ -z "$pkg" ]]; then apt-get update -qq >&2 || true; pkg="$(pick)"; fi
        if [[ -n "$pkg" ]]; then
            DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$pkg" >&2 || echo "compare.sh: apt-get install $pkg failed" >&2
        fi
    fi
fi

# 3. Glint's release binary.
echo "compare.sh: cargo build --release -p glint-cli" >&2
cargo build --release -p glint-cli >&2 || die "cargo build --release -p glint-cli failed"

# 4. The measurement.
exec "$venv/bin/python" "$here/compare.py" "$@"
