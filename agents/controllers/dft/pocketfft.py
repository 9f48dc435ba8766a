"""scipy.fft's real transforms, without what `import scipy.fft` brings along.

The field engine needs two calls: a real forward transform over some axes and
its inverse.  `import scipy.fft` also imports scipy.special (for FFTLog),
numpy.f2py and unittest: about 30 MB in an agent process whose whole budget
is 80 MB.  The transforms themselves are one compiled module,
scipy's pypocketfft, which needs nothing but numpy; this loads that module
from scipy's installed files and calls it exactly as `scipy.fft.rfftn` and
`scipy.fft.irfftn` do, so the numbers are scipy's, bit for bit (tested).
numpy.fft is no substitute: it is another pocketfft build and rounds
differently, which would move every DFT result measured so far.

Where scipy's layout is not the one this knows, it falls back to scipy.fft
itself: the same numbers, the larger process.
"""

from __future__ import annotations

import importlib.machinery
import importlib.util
import math
import sysconfig
from pathlib import Path
from types import ModuleType

import numpy as np

_NAME = "scipy.fft._pocketfft.pypocketfft"
_NONE, _BACKWARD, _FORWARD = 0, 0, 2  # pypocketfft's normalisation codes: none, norm="backward", "forward"


def _load() -> ModuleType | None:
    try:
        scipy = importlib.util.find_spec("scipy")  # finds the package without importing it
        if scipy is None or not scipy.submodule_search_locations:
            return None
        path = Path(scipy.submodule_search_locations[0], "fft", "_pocketfft",
                    "pypocketfft" + sysconfig.get_config_var("EXT_SUFFIX"))  # fmt: skip
        if not path.is_file():
            return None
        loader = importlib.machinery.ExtensionFileLoader(_NAME, str(path))
        spec = importlib.util.spec_from_file_location(_NAME, path, loader=loader)
        module = importlib.util.module_from_spec(spec)
        loader.exec_module(module)
        return module if hasattr(module, "r2c") and hasattr(module, "c2r") else None
    except (ImportError, OSError):
        return None


_pfft = _load()


def rfftn(x: np.ndarray, axes: tuple[int, ...], out: np.ndarray | None = None) -> np.ndarray:
    """`scipy.fft.rfftn(x, axes=axes)` for a real array of float32 or float64, written into `out`
    (complex64 or complex128 of the half shape) where one is given."""
    if _pfft is not None:
        return _pfft.r2c(np.ascontiguousarray(x), axes, True, _BACKWARD, out, 1)
    import scipy.fft

    return _into(scipy.fft.rfftn(x, axes=axes), out)


def irfftn(spectrum: np.ndarray, shape: tuple[int, ...], axes: tuple[int, ...],
           out: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    """`scipy.fft.irfftn(spectrum, s=shape, axes=axes)` where the spectrum already has the half
    shape of `shape` (its last axis shape[-1] // 2 + 1), as the engine's always does; written into
    `out` where one is given.  The spectrum is used up: written over.

    Why: over several axes, pocketfft's inverse first transforms all but the last axis into a
    temporary the size of the spectrum (2.7 MB a step at 16 fields of 210 x 210, held by the
    allocator or faulted in again each time), then the last axis with the 1/n scale.  Here the
    first part is done in place and the scale (the same float, 1/n rounded from long double as
    pocketfft rounds it) multiplies afterwards, as pocketfft multiplies last: the same numbers,
    bit for bit (tested), no temporary, and faster at 210 x 210."""
    if _pfft is None:
        import scipy.fft

        return _into(scipy.fft.irfftn(spectrum, s=shape, axes=axes), out)
    spectrum = np.ascontiguousarray(spectrum)
    if len(axes) == 1:
        return _pfft.c2r(spectrum, axes, shape[-1], False, _FORWARD, out, 1)
    _pfft.c2c(spectrum, axes[:-1], False, _NONE, spectrum, 1)
    out = _pfft.c2r(spectrum, axes[-1:], shape[-1], False, _NONE, out, 1)
    n = math.prod(spectrum.shape[a] for a in axes[:-1]) * shape[-1]
    out *= out.dtype.type(np.longdouble(1) / np.longdouble(n))
    return out


def _into(result: np.ndarray, out: np.ndarray | None) -> np.ndarray:
    if out is None:
        return result
    out[...] = result
    return out


def standalone() -> bool:
    """Whether the transforms run without scipy.fft (the small process)."""
    return _pfft is not None
