"""What the comparisons with Mitsuba 3 share (compare.py, equal_error.py,
agreement.py): the repository, failures reported as one line with an exit
status, the machine's CPU and Glint's version for the tables, and Mitsuba 3
loaded in this process with a libLLVM its LLVM variants do not abort on.

Python 3.11 and the standard library; ``Mitsuba`` imports the ``mitsuba``
package when it is made.
"""

from __future__ import annotations

import glob
import math
import os
import platform
import re
import subprocess
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


class Failure(Exception):
    """A failure reported as one line, with an exit status."""

    def __init__(self, message: str, status: int = 1):
        super().__init__(message)
        self.status = status


def machine_cpu() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def glint_version(binary: Path) -> str:
    try:
        r = subprocess.run([str(binary), "--version"], capture_output=True, text=True, timeout=60)
        return r.stdout.strip() or r.stderr.strip()
    except OSError as e:
        return f"unknown ({e})"


# Dr.Jit's LLVM backend (the `llvm_*` variants) compiles with the system's libLLVM,
# picking one itself. LLVM 15 aborts the process on Mitsuba's kernels ("LLVM ERROR:
# Cannot select: ... fminimum", x86 has no lowering of llvm.minimum/maximum there:
# llvm/llvm-project#53353); 19 works; 16 was not tried. So prefer the newest libLLVM
# on the machine, and refuse one older than this unless DRJIT_LIBLLVM_PATH names it.
LLVM_MIN = 17
LIBLLVM_DIRS = ["/usr/lib/x86_64-linux-gnu", "/usr/lib/aarch64-linux-gnu", "/usr/lib64", "/usr/lib", "/usr/local/lib"]


def newest_libllvm() -> tuple[int, str] | None:
    found = []
    dirs = LIBLLVM_DIRS + sorted(glob.glob("/usr/lib/llvm-*/lib"))
    for d in dirs:
        for f in glob.glob(os.path.join(d, "libLLVM*.so*")):
            m = re.match(r"libLLVM(?:-(\d+)|\.so\.(\d+))", os.path.basename(f))
            if m and os.path.isfile(f):
                found.append((int(m[1] or m[2]), f))
    return max(found) if found else None


class Mitsuba:
    def __init__(self, variant: str):
        self.libllvm = None
        explicit_llvm = "DRJIT_LIBLLVM_PATH" in os.environ
        if variant.startswith("llvm_") and not explicit_llvm:
            newest = newest_libllvm()
            if newest is None or newest[0] < LLVM_MIN:
                have = f"the newest found is LLVM {newest[0]} ({newest[1]})" if newest else "none was found"
                raise Failure(
                    f"the Mitsuba variant {variant!r} needs libLLVM {LLVM_MIN} or newer ({have}; LLVM 15 "
                    "aborts on Mitsuba's kernels). Install one (Debian 12: `apt-get install libllvm19`), set "
                    "DRJIT_LIBLLVM_PATH to one, or use --variant scalar_rgb",
                    2,
                )
            os.environ["DRJIT_LIBLLVM_PATH"] = newest[1]
        self.libllvm = os.environ.get("DRJIT_LIBLLVM_PATH") if variant.startswith("llvm_") else None
        try:
            import drjit as dr
            import mitsuba as mi
        except ImportError as e:
            raise Failure(
                f"cannot import mitsuba ({e}); run measure/mitsuba/compare.sh, which installs it in a "
                f"virtual environment, or `pip install mitsuba` for {sys.executable}",
                2,
            )
        if variant not in mi.variants():
            raise Failure(
                f"the Mitsuba variant {variant!r} is not available; this build has: {', '.join(mi.variants())}", 2
            )
        try:
            mi.set_variant(variant)
        except Exception as e:  # noqa: BLE001 (e.g. LLVM missing)
            raise Failure(f"cannot set the Mitsuba variant {variant!r}: {e}", 2)
        self.mi, self.dr, self.variant = mi, dr, variant
        self.llvm_version = None
        if variant.startswith("llvm_") and hasattr(dr.detail, "llvm_version"):
            self.llvm_version = ".".join(str(x) for x in dr.detail.llvm_version())
            major = int(dr.detail.llvm_version()[0])
            if major < LLVM_MIN:
                if not explicit_llvm:
                    raise Failure(
                        f"Dr.Jit loaded LLVM {self.llvm_version}, older than {LLVM_MIN}, which aborts on "
                        "Mitsuba's kernels; set DRJIT_LIBLLVM_PATH to a newer libLLVM or use --variant scalar_rgb",
                        2,
                    )
                print(
                    f"{Path(sys.argv[0]).name}: warning: DRJIT_LIBLLVM_PATH gives LLVM {self.llvm_version}; LLVM 15 is known to "
                    "abort on Mitsuba's kernels",
                    file=sys.stderr,
                )
        self.version = mi.__version__
        self.drjit_version = dr.__version__
        try:
            self.threads = int(dr.thread_count())
        except Exception:  # noqa: BLE001
            self.threads = os.cpu_count() or 0

    def load(self, xml: Path):
        try:
            return self.mi.load_file(str(xml))
        except Exception as e:  # noqa: BLE001
            raise Failure(f"Mitsuba could not load the exported scene {xml}: {e}")

    def render(self, scene, spp: int, seed: int):
        """Renders and waits for the result; returns (seconds, image)."""
        dr = self.dr
        t0 = time.perf_counter()
        img = self.mi.render(scene, spp=spp, seed=seed)
        dr.eval(img)
        dr.sync_thread()
        return time.perf_counter() - t0, img

    def check_and_write(self, img, path: Path) -> list[float]:
        """Writes the image (EXR) and returns its channel means; fails unless they are
        finite and some are above 0."""
        path.parent.mkdir(parents=True, exist_ok=True)
        self.mi.Bitmap(img).write(str(path))
        means = [float(x) for x in self.dr.mean(img, axis=(0, 1)).array]
        if not all(math.isfinite(m) for m in means) or max(means) <= 0:
            raise Failure(f"Mitsuba's image {path} is implausible: channel means {means}")
        return means
