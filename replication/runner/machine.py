"""What machine computed a run, as far as its numbers can depend on it.

numpy, OpenBLAS, OpenCV and numba each pick their code paths when they load, by the CPU's features
(AVX-512, AVX2, FMA, NEON): a sum over a BLAS kernel, a transcendental or a single-precision image
filter then rounds differently on another machine, and a run computed there agrees with the record in
all but its last digits, or parts from it where a rounding flips a decision (docs/reproducibility.md).
:func:`machine` says which paths this process took: the CPU beside its name (family, model, stepping:
``/proc/cpuinfo`` where there is one), the SIMD features numpy found, the BLAS with its kernel and
threads (threadpoolctl), the features OpenCV dispatches to, numba's target CPU and vector features, and
the C library (its libm computes the scalar transcendentals).
Two runs whose :class:`Machine` and library versions are equal were computed by the same code paths.
"""

import platform
import re
from dataclasses import dataclass
from functools import cache
from pathlib import Path

VECTOR = re.compile(r"avx|fma|sse|neon|sve|asimd|f16c")  # numba's (LLVM's) features that change its code


@dataclass(frozen=True)
class Machine:
    cpu: str  # the CPU's model name ("AMD EPYC")
    family: int | None  # x86's cpu family, model and stepping (None where /proc/cpuinfo has none)
    model: int | None
    stepping: int | None
    simd: tuple[str, ...]  # the SIMD features numpy found and may dispatch to (NPY_DISABLE_CPU_FEATURES masks them)
    blas: tuple[str, ...]  # each BLAS loaded: library, version, kernel, threads ("openblas 0.3.31 Haswell, 1 thread")
    opencv: str  # OpenCV's dispatch: its CPU features line, available ones marked * (OPENCV_CPU_DISABLE)
    numba: str  # numba's target CPU and its vector features ("znver3 +avx +avx2 +fma ...", NUMBA_CPU_NAME)
    libc: str  # the C library, whose libm computes numba's and numpy's scalar transcendentals ("glibc 2.36")

    @classmethod
    def of(cls, data: dict) -> "Machine":
        """The machine a record's ``machine_detail`` (a mapping, its sequences as lists) describes."""
        return cls(**{k: tuple(v) if isinstance(v, list) else v for k, v in data.items()})

    def __str__(self) -> str:
        where = (f" (family {self.family}, model {self.model}, stepping {self.stepping})"
                 if self.family is not None else "")
        return (f"{self.cpu}{where}; numpy SIMD {' '.join(self.simd) or 'none'}; "
                f"BLAS {'; '.join(self.blas) or 'none'}; OpenCV {self.opencv}; numba {self.numba}; "
                f"{self.libc or 'libc unknown'}")


def machine() -> Machine:
    """This process's :class:`Machine`: the BLAS's threads as they are now (one in a run,
    :func:`~replication.runner.memory.one_thread`), the rest as the libraries chose when they loaded."""
    return Machine(**_loaded(), blas=_blas())


@cache
def _loaded() -> dict:
    """What does not change in a process: the CPU, and the paths numpy, OpenCV and numba chose."""
    cpu = _cpuinfo()
    family, model, stepping = (int(cpu[k]) if cpu.get(k, "").isdigit() else None
                               for k in ("cpu family", "model", "stepping"))
    return {"cpu": cpu.get("model name") or platform.processor(), "family": family, "model": model,
            "stepping": stepping, "simd": _numpy(), "opencv": _opencv(), "numba": _numba(),
            "libc": " ".join(platform.libc_ver()).strip()}


def _cpuinfo() -> dict[str, str]:
    """The first processor's fields in ``/proc/cpuinfo`` (Linux); none elsewhere."""
    try:
        lines = Path("/proc/cpuinfo").read_text().split("\n\n")[0].splitlines()
    except OSError:
        return {}
    return {key.strip(): value.strip() for key, _, value in (line.partition(":") for line in lines)}


def _numpy() -> tuple[str, ...]:
    try:
        from numpy._core._multiarray_umath import __cpu_features__
    except ImportError:  # numpy 1.x
        from numpy.core._multiarray_umath import __cpu_features__
    return tuple(name for name, found in __cpu_features__.items() if found)


def _blas() -> tuple[str, ...]:
    """Each BLAS numpy, scipy and OpenCV load (each ships its own), whichever of them a run imported."""
    import cv2  # noqa: F401
    import scipy.linalg  # noqa: F401
    from threadpoolctl import threadpool_info

    return tuple(sorted(f"{p['internal_api']} {p['version']} {p.get('architecture') or ''}".rstrip()
                 + f", {p['num_threads']} thread{'s' if p['num_threads'] != 1 else ''}"
                 for p in threadpool_info() if p["user_api"] == "blas"))


def _opencv() -> str:
    import cv2

    return cv2.getCPUFeaturesLine()


def _numba() -> str:
    from llvmlite import binding
    from numba.core import config

    name = config.CPU_NAME or binding.get_host_cpu_name()
    features = config.CPU_FEATURES if config.CPU_NAME else binding.get_host_cpu_features().flatten()
    enabled = sorted(f for f in (features or "").split(",") if f.startswith("+") and VECTOR.search(f))
    return " ".join([name, *enabled])
