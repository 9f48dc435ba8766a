"""Dynamic neural fields declared as data and stepped by one engine.

An architecture is a list of `Field`s (dynamic: Amari's equation 1 of the DFT
paper, Euler-stepped with dt = 1 step), `Input`s (images a robot interface
writes: goal, map, position, heading, proximity) and `Coupling`s between them
(amplitude, optional normalised Gaussian kernel, shift in cells, or a
reduction to one number: the max or sum of a source's output).  `Engine`
steps any such table, as cedar and COSIVINA do.

Why the frequency domain: every coupling and lateral kernel is a circular
convolution, so each source's output is transformed once, every kernel and
shift is one complex multiply-add there (a (target, source) pair's couplings
are summed into one transfer function at build time), and each target is
transformed back once.  At 100 x 100 cells that is 16 + 16 transforms a step
for the SPA architecture's 16 fields, whatever the number of couplings.

Conventions (COSIVINA's, docs/dft.md):
- u <- u + (-u + h + inputs + noise * xi) / tau, then f(u) = 1 / (1 + exp(-beta u));
  every coupling reads the previous step's outputs (a synchronous update);
- Gaussian kernels are separable 1D Gaussians on +-ceil(5 sigma) cells (at most
  half the field), each normalised to sum 1, so the amplitude is the kernel's
  total mass; lateral kernels are c_exc * G(s_exc) - c_inh * G(s_inh) + c_global;
- shifts move activity by the given cells; everything wraps around (circular).
"""

from __future__ import annotations

import hashlib
import math
import time
from dataclasses import dataclass

import numpy as np

from agents.controllers.dft import pocketfft
from agents.controllers.dft.params import Lateral
from swarm.core import rng_scalar
from swarm.core.kernels import exported, njit
from swarm.core.rng import mix64

DTYPE = np.float32
CDTYPE = np.complex64


@dataclass(frozen=True)
class Field:
    name: str
    shape: tuple[int, ...]
    tau: float  # steps
    h: float
    beta: float
    noise: float = 0.0  # amplitude of the per-cell, per-step noise
    lateral: Lateral = Lateral()


@dataclass(frozen=True)
class Input:
    """An image set from outside (sensors, goal, map); its output is the image itself."""

    name: str
    shape: tuple[int, ...]


@dataclass(frozen=True)
class Coupling:
    source: str
    target: str
    amplitude: float
    sigma: float | None = None  # normalised Gaussian kernel; None: a plain (shifted) copy
    shift: tuple[int, ...] | None = None  # cells the activity moves by
    reduce: str | None = None  # "max" | "sum": a uniform input amplitude * reduce(source output)


@dataclass(frozen=True)
class Architecture:
    fields: tuple[Field, ...]
    inputs: tuple[Input, ...]
    couplings: tuple[Coupling, ...]

    def check(self) -> None:
        """Raise ValueError (one line) for a table the engine cannot step."""
        names = [f.name for f in self.fields] + [i.name for i in self.inputs]
        if len(set(names)) != len(names):
            raise ValueError(f"architecture: a name is used twice in {sorted(names)}")
        shape = {f.name: f.shape for f in self.fields} | {i.name: i.shape for i in self.inputs}
        dynamic = {f.name for f in self.fields}
        for c in self.couplings:
            if c.source not in shape or c.target not in dynamic:
                raise ValueError(f"architecture: coupling {c.source} -> {c.target}: the source must be a field or "
                                 f"input and the target a field")  # fmt: skip
            if c.reduce is None and shape[c.source] != shape[c.target]:
                raise ValueError(f"architecture: coupling {c.source} -> {c.target} joins shapes "
                                 f"{shape[c.source]} and {shape[c.target]}; use reduce='max' or 'sum'")  # fmt: skip
            if c.reduce not in (None, "max", "sum"):
                raise ValueError(f"architecture: coupling {c.source} -> {c.target}: reduce is max or sum")
            if c.shift is not None and len(c.shift) != len(shape[c.target]):
                raise ValueError(f"architecture: coupling {c.source} -> {c.target}: shift has the wrong length")


def gauss_1d(n: int, sigma: float) -> np.ndarray:
    """A normalised Gaussian on +-ceil(5 sigma) cells (at most half the axis), centred on
    cell 0 of an axis of n cells, wrapped."""
    half = min(math.ceil(5 * sigma), n // 2)
    x = np.arange(-half, half + 1)
    g = np.exp(-(x**2) / (2 * sigma**2))
    g /= g.sum()
    out = np.zeros(n)
    np.add.at(out, x % n, g)
    return out


def gauss_image(shape: tuple[int, ...], sigma: float) -> np.ndarray:
    img = np.ones(())
    for n in shape:
        img = np.multiply.outer(img, gauss_1d(n, sigma))
    return img


def kernel_image(shape: tuple[int, ...], amplitude: float, sigma: float | None, shift) -> np.ndarray:
    if sigma is None:
        img = np.zeros(shape)
        img[(0,) * len(shape)] = 1.0
    else:
        img = gauss_image(shape, sigma)
    img = amplitude * img
    return np.roll(img, tuple(shift), axis=tuple(range(len(shape)))) if shift else img


def lateral_image(shape: tuple[int, ...], lat: Lateral) -> np.ndarray:
    img = np.full(shape, float(lat.c_global))
    if lat.c_exc:
        img += lat.c_exc * gauss_image(shape, lat.s_exc)
    if lat.c_inh:
        img -= lat.c_inh * gauss_image(shape, lat.s_inh)
    return img


def _tanh_half(scaled: np.ndarray) -> np.ndarray:
    """The sigmoid f(u) = 1 / (1 + exp(-beta u)) as 0.5 + 0.5 tanh(x), in place, from x = beta u / 2 (the
    same function; numpy's float32 tanh is vectorised, exp through numba is not).  The rest is one
    compiled pass; x * 0.5 is exact, so its numbers are numpy's multiply and add."""
    np.tanh(scaled, out=scaled)
    _half_up(scaled.reshape(-1))
    return scaled


@exported("dft_half_up", "void(float32[:])")
@njit(cache=True)
def _half_up(x):
    for c in range(x.size):
        x[c] = x[c] * np.float32(0.5) + np.float32(0.5)


_IH_SCALE = np.float32(1.0 / 65536.0)
_M16 = np.uint64(0xFFFF)
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)


@njit(cache=True, inline="always")
def normal_ih(key, k):
    """An approximately standard normal number for cell k: the sum of four 16-bit uniforms of one
    SplitMix64 word (Irwin-Hall), centred and scaled to variance 1 (bounded at +-3.46)."""
    z = mix64(key + np.uint64(k) * _GOLDEN)
    s = (z & _M16) + ((z >> np.uint64(16)) & _M16) + ((z >> np.uint64(32)) & _M16) + (z >> np.uint64(48))
    return (np.float32(s) * _IH_SCALE - np.float32(2.0)) * np.float32(1.7320508075688772)


@exported("dft_fill_noise", "void(uint64, float32[:])")
@njit(cache=True)
def fill_noise(key, out):
    """Field noise for every cell of `out` (flat float32), keyed by one 64-bit word."""
    for k in range(out.size):
        out[k] = normal_ih(key, k)


@exported("dft_noise_key", "uint64(int64, int64, int64, int64)")
@njit(cache=True)
def noise_key(seed, agent, tick, stream):
    h = mix64(np.uint64(seed) + _GOLDEN * np.uint64(agent + 1))
    h = mix64(h ^ (np.uint64(tick) * np.uint64(0xD1B54A32D192ED03)))
    return mix64(h ^ (np.uint64(stream) * np.uint64(0xA24BAED4963EE407)))


@exported("dft_euler", "void(float32[:, :], float32[:, :], float32[:], float32[:], float32[:], float32[:], "
          "float32[:], uint64)")  # fmt: skip
@njit(cache=True)
def _euler(u, io, uniform, taus, hs, amps, half_betas, key):
    """u[k] += (-u + h + input + amp * xi) / tau for every field k of a stack (F, n), the input being
    io[k] plus the field's uniform part; io[k] then gets u[k] * beta_k / 2, the argument of the
    output's tanh (`_tanh_half`).  One pass in place, where numpy took four (and two arrays: a loop
    that reads one array and writes another that may be the same one is not vectorised)."""
    n = u.shape[1]
    for k in range(u.shape[0]):
        inv, h, amp, uni, hb = np.float32(1.0) / taus[k], hs[k], amps[k], uniform[k], half_betas[k]
        fkey = mix64(key ^ (np.uint64(k + 1) * _GOLDEN))
        uk, xk = u[k], io[k]
        if amp != 0:
            for c in range(n):
                v = uk[c] + (h - uk[c] + (xk[c] + uni) + amp * normal_ih(fkey, c)) * inv
                uk[c] = v
                xk[c] = v * hb
        else:
            for c in range(n):
                v = uk[c] + (h - uk[c] + (xk[c] + uni)) * inv
                uk[c] = v
                xk[c] = v * hb


@exported("dft_mac", "void(complex64[:, :], complex64[:, :], complex64[:, :], int64[:], boolean[:], int64[:], "
          "int64[:], complex64[:, :])")  # fmt: skip
@njit(cache=True)
def _mac(acc, dyn, ext, src, is_ext, tgt, kernel, transfer):
    """acc[t] = sum over pairs p of transfer[kernel[p]] * spectrum of source p (dynamic or input)."""
    acc[:] = 0
    m = acc.shape[1]
    for p in range(len(src)):
        a, k = acc[tgt[p]], transfer[kernel[p]]
        s = ext[src[p]] if is_ext[p] else dyn[src[p]]
        for c in range(m):
            a[c] += k[c] * s[c]


class _Group:
    """The fields and inputs of one shape, stepped together in the frequency domain."""

    def __init__(self, shape: tuple[int, ...], fields: list[Field], inputs: list[Input], couplings: list[Coupling],
                 keep_inputs: bool):  # fmt: skip
        self.shape, self.fields, self.inputs = shape, fields, inputs
        self.label = "x".join(map(str, shape))
        self.axes = tuple(range(1, len(shape) + 1))
        self.size = int(np.prod(shape))
        fi = {f.name: k for k, f in enumerate(fields)}
        ii = {x.name: k for k, x in enumerate(inputs)}
        # each (target, source) pair's kernels, summed into one image and transformed one pair at a
        # time: at 1 cm over a 2 m maze, holding every image at once cost an agent ~40 MB it never gave back
        parts: dict[tuple[int, bool, int], list] = {}
        for k, f in enumerate(fields):
            lat = f.lateral
            if lat.c_exc or lat.c_inh or lat.c_global:
                parts[(fi[f.name], False, k)] = [lambda lat=lat: lateral_image(shape, lat)]
        for c in couplings:
            ext = c.source in ii
            key = (fi[c.target], ext, ii[c.source] if ext else fi[c.source])
            parts.setdefault(key, []).append(lambda c=c: kernel_image(shape, c.amplitude, c.sigma, c.shift))
        keys = sorted(parts)
        self.tgt = np.array([k[0] for k in keys], np.int64)
        self.is_ext = np.array([k[1] for k in keys], np.bool_)
        self.src = np.array([k[2] for k in keys], np.int64)
        half = self._spectrum(np.zeros((1, *shape), DTYPE)).shape[1:]
        # pairs with the same kernel (the SPA's four directions repeat theirs) share one transfer function
        spectra: dict[bytes, int] = {}
        rows: list[np.ndarray] = []
        self.kernel = np.empty(len(keys), np.int64)
        for p, key in enumerate(keys):
            image = parts[key][0]()
            for more in parts[key][1:]:
                image = image + more()
            spectrum = self._spectrum(image[None].astype(DTYPE)).reshape(-1)
            self.kernel[p] = spectra.setdefault(hashlib.sha1(spectrum).digest(), len(rows))
            if self.kernel[p] == len(rows):
                rows.append(spectrum)
        self.transfer = np.stack(rows) if rows else np.zeros((0, int(np.prod(half))), CDTYPE)
        self.half = half
        n = len(fields)
        self.u = np.empty((n, self.size), DTYPE)
        self.out = np.empty((n, self.size), DTYPE)
        # the fields' inputs: their own buffer, or (keep_inputs=False) the outputs' one, which holds nothing
        # between the forward transform and the Euler pass that writes the next outputs over the inputs
        self.inp = np.zeros((n, self.size), DTYPE) if keep_inputs else self.out
        self.uniform = np.zeros(n, DTYPE)  # reductions from other fields, added to every cell
        self.taus = np.array([f.tau for f in fields], DTYPE)
        self.hs = np.array([f.h for f in fields], DTYPE)
        self.amps = np.array([f.noise for f in fields], DTYPE)
        self.half_betas = np.array([DTYPE(0.5 * f.beta) for f in fields], DTYPE)
        self.images = np.zeros((len(inputs), self.size), DTYPE)
        self.ext_spec = np.zeros((len(inputs), int(np.prod(half))), CDTYPE)
        self.dirty = np.ones(len(inputs), np.bool_)
        self.acc = np.zeros((n, int(np.prod(half))), CDTYPE)
        self.dyn = np.zeros((n, int(np.prod(half))), CDTYPE)  # the fields' outputs, transformed
        self.reset()

    @property
    def keeps_inputs(self) -> bool:
        return self.inp is not self.out

    def _spectrum(self, stack: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        return pocketfft.rfftn(stack, self.axes, out).astype(CDTYPE, copy=False)

    def reset(self) -> None:
        for k, f in enumerate(self.fields):
            self.u[k] = f.h
        self._outputs()

    def _outputs(self) -> None:
        np.multiply(self.u, self.half_betas[:, None], out=self.out)
        _tanh_half(self.out)

    def inputs_from_couplings(self) -> None:
        """Every field's input from the current outputs (before any field is updated)."""
        if len(self.src) == 0:
            self.inp[:] = 0
            return
        if self.dirty.any():  # inputs whose image changed: transformed together
            changed = np.flatnonzero(self.dirty)
            self.ext_spec[changed] = self._spectrum(self.images[changed].reshape(-1, *self.shape)).reshape(
                len(changed), -1)  # fmt: skip
            self.dirty[:] = False
        # the step's transforms write into buffers kept for them: no ~3 MB arrays a step for the allocator
        self._spectrum(self.out.reshape(-1, *self.shape), self.dyn.reshape(-1, *self.half))
        _mac(self.acc, self.dyn, self.ext_spec, self.src, self.is_ext, self.tgt, self.kernel, self.transfer)
        pocketfft.irfftn(self.acc.reshape(-1, *self.half), self.shape, self.axes, self.inp.reshape(-1, *self.shape))

    def update(self, key) -> None:
        if self.keeps_inputs:  # the step works on the outputs' buffer; the kept inputs get the reductions too
            np.copyto(self.out, self.inp)
            self.inp += self.uniform[:, None]
        _euler(self.u, self.out, self.uniform, self.taus, self.hs, self.amps, self.half_betas, key)
        _tanh_half(self.out)  # the outputs from the scaled activations _euler left in them


class Engine:
    """Steps an `Architecture`: fields of one shape share their transforms."""

    def __init__(self, arch: Architecture, keep_inputs: bool = True):
        """keep_inputs=False: no buffer for what each field received (`input_of`); a robot's fields step
        the same to the bit without it, and at 210 x 210 cells it is 2.8 MB of an agent process."""
        arch.check()
        self.arch = arch
        shapes = list(dict.fromkeys([f.shape for f in arch.fields]))
        self.groups: list[_Group] = []
        self.where: dict[str, tuple[int, int, bool]] = {}  # name -> (group, index, is input)
        for g, shape in enumerate(shapes):
            fields = [f for f in arch.fields if f.shape == shape]
            inputs = [x for x in arch.inputs if x.shape == shape]
            names = {f.name for f in fields}
            conv = [c for c in arch.couplings if c.reduce is None and c.target in names]
            self.groups.append(_Group(shape, fields, inputs, conv, keep_inputs))
            self.where |= {f.name: (g, k, False) for k, f in enumerate(fields)}
            self.where |= {x.name: (g, k, True) for k, x in enumerate(inputs)}
        for x in arch.inputs:
            if x.name not in self.where:
                raise ValueError(f"architecture: input {x.name} has the shape of no field")
        self.reductions = [(self.where[c.source], self.where[c.target], c.amplitude, c.reduce)
                           for c in arch.couplings if c.reduce is not None]  # fmt: skip

    def reset(self) -> None:
        for g in self.groups:
            g.reset()

    def set_input(self, name: str, image: np.ndarray) -> None:
        g, k, ext = self.where[name]
        assert ext, f"{name} is a field, not an input"
        grp = self.groups[g]
        grp.images[k] = np.asarray(image, DTYPE).ravel()
        grp.dirty[k] = True

    def step(self, key, times: dict[str, float] | None = None) -> None:
        """One step of every field (key: a 64-bit word from noise_key; each field draws its own noise).
        `times`, if given, accumulates seconds per shape group: couplings (transforms, kernels, the
        transforms back, reductions) and fields (the Euler step, noise and outputs)."""
        clock = time.perf_counter if times is not None else None
        t0 = clock() if clock else 0.0
        for grp in self.groups:
            grp.uniform[:] = 0
        for (gs, ks, ext), (gt, kt, _), amp, how in self.reductions:
            src = self.groups[gs].images[ks] if ext else self.groups[gs].out[ks]
            value = src.max() if how == "max" else src.sum(dtype=np.float64)
            self.groups[gt].uniform[kt] += DTYPE(amp * value)
        for grp in self.groups:
            grp.inputs_from_couplings()
            if clock:
                t1 = clock()
                times[f"couplings {grp.label}"] = times.get(f"couplings {grp.label}", 0.0) + t1 - t0
                t0 = t1
        for g, grp in enumerate(self.groups):
            grp.update(np.uint64(rng_scalar.mix64(int(key) ^ (g + 1))))  # swarm.core.rng's mix64, bit for bit
            if clock:
                t1 = clock()
                times[f"fields {grp.label}"] = times.get(f"fields {grp.label}", 0.0) + t1 - t0
                t0 = t1

    # ------------------------------------------------------------ access

    def _view(self, name: str, what: str) -> np.ndarray:
        g, k, ext = self.where[name]
        grp = self.groups[g]
        arr = grp.images[k] if ext else getattr(grp, what)[k]
        return arr.reshape(grp.shape)

    def u(self, name: str) -> np.ndarray:
        return self._view(name, "u")

    def output(self, name: str) -> np.ndarray:
        return self._view(name, "out")

    def input_of(self, name: str) -> np.ndarray:
        """Everything the field received in the last step (couplings, inputs and reductions; not the noise)."""
        if not self.groups[self.where[name][0]].keeps_inputs:
            raise ValueError("this engine keeps no inputs: build it with keep_inputs=True to read them")
        return self._view(name, "inp")

    def state(self) -> dict[str, np.ndarray]:
        """Everything that evolves (the activations; outputs follow from them), for snapshots: the
        engine's own arrays, not copies (MBs at 210 x 210; the agent encodes them before the next step)."""
        out = {f"u{g}": grp.u for g, grp in enumerate(self.groups)}
        out |= {f"img{g}": grp.images for g, grp in enumerate(self.groups)}
        return out

    def checked(self, state: dict[str, np.ndarray]) -> list[tuple[np.ndarray, np.ndarray]]:
        """Every group's (u, images) from a state, in the engine's shapes and dtype, changing nothing: raises
        on any missing or misshapen array.  Views where the state's arrays already fit (no MB-sized copies)."""
        return [(np.asarray(state[f"u{g}"], DTYPE).reshape(grp.u.shape),
                 np.asarray(state[f"img{g}"], DTYPE).reshape(grp.images.shape))
                for g, grp in enumerate(self.groups)]  # fmt: skip

    def put(self, arrays: list[tuple[np.ndarray, np.ndarray]]) -> None:
        """Write what `checked` gave (it cannot fail half-way)."""
        for grp, (u, images) in zip(self.groups, arrays, strict=True):
            grp.u[...] = u
            grp.images[...] = images
            grp.dirty[:] = True
            grp._outputs()
