"""Streaming generators of the stochastic IMU error processes, per axis, block by block.

Each generator draws from its own random stream in sample-major order and carries its state between blocks, so a
record cut into any blocks is bit-identical to the record made in one call. A sample represents the interval
(t[k-1], t[k]] of length ``dt``; every discretisation below is exact (or accurate to O(dt/tau)) for the continuous
process, so the same physical spec gives the same Allan deviation at any sample rate.

The coloured processes (flicker, first-order Gauss-Markov) are linear filters of white noise, run by
:class:`ShapedNoise` as matrix products over frames of samples: numpy and BLAS only, so that a run without a
quantizer or a bandwidth never starts numba (its first kernel costs a process about 0.5 s of CPU). The two filters
of a deterministic input, the quantizer and the bandwidth low-pass, run compiled (:mod:`.kernels`).
"""
from __future__ import annotations

import math

import numpy as np

# Flicker band: correlation times log-spaced at this many per decade (ripple of the ADEV floor < 1 %).
FLICKER_POLES_PER_DECADE = 2
# Flicker poles faster than 1 / (this * dt) are dropped: the shared-noise discretisation is accurate for p*dt <= 0.1.
FLICKER_MIN_TAU_SAMPLES = 10.0


class WhiteNoise:
    """White noise of two-sided PSD ``n**2`` averaged over each sample interval: sample std ``n / sqrt(dt)``."""

    def __init__(self, n: float, dt: float, rng: np.random.Generator, axes: int = 3):
        self.std, self.rng, self.axes = n / math.sqrt(dt), rng, axes

    def block(self, count: int) -> np.ndarray:
        return self.std * self.rng.standard_normal((count, self.axes))


class RandomWalk:
    """Rate random walk: integrated white noise of two-sided PSD ``k**2``, sampled at the interval ends.

    Starts at zero (the turn-on bias carries the initial offset). Its Allan variance is
    ``k^2 tau / 3 + k^2 dt^2 / (6 tau)``: the sampling term is below 0.5 % beyond ten samples.
    """

    def __init__(self, k: float, dt: float, rng: np.random.Generator, axes: int = 3):
        self.step, self.rng = k * math.sqrt(dt), rng
        self.value = np.zeros((1, axes))

    def block(self, count: int) -> np.ndarray:
        steps = self.step * self.rng.standard_normal((count, self.value.shape[1]))
        out = np.cumsum(np.concatenate([self.value, steps]), axis=0)[1:]
        self.value = out[-1:].copy()
        return out


def flicker_design(b: float, tau_min: float, tau_max: float, dt: float):
    """Poles p_i (1/s) and partial-fraction weights c_i of the flicker shaping filter.

    H(s) = g * prod_i (s + z_i) / (s + p_i) * 1 / (s + p_M) with poles log-spaced over [1/tau_max, 1/tau_min] and a
    zero at the geometric mean of each pair of adjacent poles, so |H(j w)|^2 ~ 1/w inside the band. Its partial
    fractions H(s) = sum_i c_i / (s + p_i) make the process a sum of first-order Gauss-Markov processes driven by
    one common unit white noise; g is set so that the two-sided PSD equals B^2 / (2 pi f) in the band (IEEE 952),
    i.e. the Allan floor is 0.664 B.
    """
    tau_min = max(tau_min, FLICKER_MIN_TAU_SAMPLES * dt)
    decades = math.log10(tau_max / tau_min)
    m = max(2, int(round(decades * FLICKER_POLES_PER_DECADE)) + 1)
    p = np.logspace(-math.log10(tau_max), -math.log10(tau_min), m)
    z = np.sqrt(p[:-1] * p[1:])
    c = np.array([np.prod(z - pi) / np.prod(np.delete(p, i) - pi) for i, pi in enumerate(p)])
    # calibrate on the central part of the band, away from the edges
    w = np.logspace(math.log10(p[1]), math.log10(p[-2]), 64) if m > 3 else np.sqrt(p[:1] * p[-1:])
    h2 = np.abs(np.sum(c[None, :] / (1j * w[:, None] + p[None, :]), axis=1)) ** 2
    gain = b / math.sqrt(math.exp(np.mean(np.log(w * h2))))
    return p, gain * c


# Samples per frame of :class:`FrameFilter`: the outputs of a frame are one (FRAME x FRAME) matrix product.
FRAME = 64


# Frames per batch of :class:`FrameFilter` and :class:`ShapedNoise`: batches are aligned to the record start.
BATCH_FRAMES = 64
BATCH_MAX_RADIUS = 0.5  # FrameFilter: batches of one frame when A^FRAME decays slower than this


class FrameFilter:
    """The linear filter s[k] = A s[k-1] + B x[k], y[k] = C s[k-1] + D x[k] (n states, one input and one output per
    axis) on ``axes`` independent axes, vectorised over time.

    Frames of L = :data:`FRAME` samples, aligned to the record start: inside a frame y = T x + P s0, with the
    lower-triangular Toeplitz matrix of the impulse response (T[j, j] = D, T[j, l] = C A^(j-l-1) B) and
    P[j] = C A^j; the state steps from frame to frame as s0' = A^L s0 + G x (G[:, l] = A^(L-1-l) B). The
    frame-start states of a batch of :data:`BATCH_FRAMES` frames (aligned to the record start) follow in closed
    form, s0 of frame f = sum_{g<f} (A^L)^(f-1-g) G x_g + (A^L)^f s0 of the batch: one block lower-triangular
    matrix product per batch instead of a loop over frames. A slow filter (A^L with a spectral radius above
    :data:`BATCH_MAX_RADIUS`: poles near 1, where the powers of a nearly defective A lose digits; 1.3e-9 against
    6e-11 of inputs ~100 for 0.5 Hz at 1 kHz) keeps batches of one frame, the frame-by-frame recursion. An
    unfinished batch is zero-padded and kept: the next call computes it again with its new samples. Every product has the same shape whatever the caller's blocks,
    and the padding only adds exact zeros (every matrix is lower-triangular in time), so a record cut into any
    blocks is bit-identical to the record in one call.
    """

    def __init__(self, a, b, c, d: float, state: np.ndarray):
        b, c = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (b, c))
        n = b.size
        a = np.asarray(a, dtype=float).reshape(n, n)
        frame = FRAME
        powers = np.empty((frame + 1, n, n))
        powers[0] = np.eye(n)
        for j in range(frame):
            powers[j + 1] = a @ powers[j]
        count = BATCH_FRAMES if np.abs(np.linalg.eigvals(powers[frame])).max() <= BATCH_MAX_RADIUS else 1
        self.count = count
        h = np.concatenate([[d], c @ powers[:frame - 1] @ b])
        lag = np.arange(frame)[:, None] - np.arange(frame)[None, :]
        self.toeplitz = np.where(lag >= 0, h[np.clip(lag, 0, None)], 0.0)     # (L, L)
        self.carry = c @ powers[:frame]                                         # (L, n): C A^j
        self.drive = (powers[frame - 1::-1] @ b).T.copy()                       # (n, L): A^(L-1-l) B
        steps = np.empty((count + 1, n, n))                                     # (A^L)^k
        steps[0] = np.eye(n)
        for k in range(count):
            steps[k + 1] = powers[frame] @ steps[k]
        scan = np.zeros((count, n, count, n))
        for f in range(1, count):
            scan[f, :, :f, :] = steps[f - 1::-1].transpose(1, 0, 2)            # block (f, g): (A^L)^(f-1-g)
        self.scan = scan.reshape(count * n, count * n)
        self.from_start = steps[:count].reshape(count * n, n)                   # block f: (A^L)^f
        self.to_end = np.concatenate([steps[count - 1 - g] for g in range(count)], axis=1)  # block g: (A^L)^(C-1-g)
        self.a_batch = steps[count]
        self.state = np.array(state, dtype=float).reshape(n, -1)               # at the start of the open batch
        self.pending = np.empty((0, self.state.shape[1]))                       # inputs of the open batch

    def apply(self, x: np.ndarray) -> np.ndarray:
        """Filter the next samples ``x`` (count, axes) of the record."""
        frame, count, n, axes = FRAME, self.count, self.state.shape[0], self.state.shape[1]
        done, total = self.pending.shape[0], self.pending.shape[0] + x.shape[0]
        batch = frame * count
        full = total // batch
        frames = np.zeros((-(-total // batch), count, frame, axes))
        flat = frames.reshape(-1, axes)
        flat[:done], flat[done:total] = self.pending, x
        drive = np.matmul(self.drive, frames).reshape(frames.shape[0], count * n, axes)  # G x_g, stacked
        y = np.empty(frames.shape)
        s = self.state
        for j in range(frames.shape[0]):
            starts = (self.scan @ drive[j] + self.from_start @ s).reshape(count, n, axes)
            y[j] = np.matmul(self.toeplitz, frames[j]) + np.matmul(self.carry, starts)
            if j < full:
                s = self.a_batch @ s + self.to_end @ drive[j]
        self.state = s
        self.pending = flat[full * batch:total].copy()
        return y.reshape(-1, axes)[done:total]


class ShapedNoise:
    """Unit white noise w through n first-order filters sharing it, s_i[k] = a_i s_i[k-1] + b_i w[k], summed as
    y[k] = sum_i c_i s_i[k-1] + d w[k], on ``axes`` independent axes (state (n, axes)).

    The :class:`FrameFilter` products without its frame-to-frame loop: the noise is drawn and filtered in whole
    batches of :data:`BATCH_FRAMES` frames aligned to the record start and handed out from a buffer, so the
    frame-start states of a batch follow in closed form (s0 of frame f = sum_{g<f} a^(L (f-1-g)) G w_g
    + a^(L f) s0 of the batch, one (C x C) product per state) and every product has one shape whatever the
    caller's blocks: a record cut into any blocks is bit-identical to the record in one call.
    """

    def __init__(self, a, b, c, d: float, state: np.ndarray, rng: np.random.Generator):
        a, b, c = (np.atleast_1d(np.asarray(v, dtype=float)) for v in (a, b, c))
        frame, count = FRAME, BATCH_FRAMES
        pw = a[None, :] ** np.arange(frame + 1)[:, None]                   # (L + 1, n): a^j
        h = np.concatenate([[d], pw[:frame - 1] @ (c * b)])
        lag = np.arange(frame)[:, None] - np.arange(frame)[None, :]
        self.toeplitz = np.where(lag >= 0, h[np.clip(lag, 0, None)], 0.0)  # (L, L)
        self.carry = pw[:frame] * c                                          # (L, n): c a^j
        self.drive = (pw[frame - 1::-1] * b).T.copy()                        # (n, L): a^(L-1-l) b
        a_frame = pw[frame]
        steps = np.arange(count)[:, None] - np.arange(count)[None, :] - 1   # f - 1 - g
        self.scan = np.where(steps >= 0, a_frame[:, None, None] ** np.clip(steps, 0, None), 0.0)  # (n, C, C)
        self.from_start = (a_frame[:, None] ** np.arange(count)[None, :])[:, :, None]           # (n, C, 1)
        self.to_end = (a_frame[:, None] ** np.arange(count - 1, -1, -1)[None, :])[:, None, :]   # (n, 1, C)
        self.a_batch = a_frame ** count
        self.state = np.array(state, dtype=float).reshape(a.size, -1)
        self.rng = rng
        self.ready = np.empty((0, self.state.shape[1]))

    def _batch(self) -> np.ndarray:
        axes = self.state.shape[1]
        frame, count = FRAME, BATCH_FRAMES
        w = self.rng.standard_normal((count, frame, axes))               # sample-major: the stream's order
        drive = np.matmul(self.drive, w).transpose(1, 0, 2)                 # (n, C, axes)
        starts = np.matmul(self.scan, drive) + self.from_start * self.state[:, None, :]
        self.state = self.a_batch[:, None] * self.state + np.matmul(self.to_end, drive)[:, 0]
        y = np.matmul(self.toeplitz, w) + np.matmul(self.carry, starts.transpose(1, 0, 2))
        return y.reshape(count * frame, axes)

    def block(self, count: int) -> np.ndarray:
        parts, have = [self.ready], self.ready.shape[0]
        while have < count:
            parts.append(self._batch())
            have += parts[-1].shape[0]
        merged = np.concatenate(parts) if len(parts) > 1 else self.ready
        self.ready = merged[count:].copy()
        return merged[:count]


def gauss_markov(sigma: float, tau_s: float, dt: float, rng: np.random.Generator, axes: int = 3) -> ShapedNoise:
    """First-order Gauss-Markov bias of standard deviation ``sigma`` and correlation time ``tau_s``, started from its
    stationary distribution: the exact AR(1) recursion of :func:`simkit.processes.ar1_coefficients`."""
    from ..processes import ar1_coefficients

    phi, drive = ar1_coefficients(sigma, tau_s, dt)
    return ShapedNoise(phi, drive, phi, drive, sigma * rng.standard_normal(axes), rng)


class Flicker(ShapedNoise):
    """Bias instability as flicker (1/f) noise of IEEE coefficient ``b`` over correlation times [tau_min, tau_max].

    Sum of first-order Gauss-Markov branches sharing one white noise (see :func:`flicker_design`): one normal
    draw per sample and axis, memory O(branches), started from the stationary distribution. Each branch is
    x_k = exp(-p dt) x_{k-1} + (1 - exp(-p dt)) / p * w_k with w_k the interval mean of the unit white noise.
    """

    def __init__(self, b: float, tau_min: float, tau_max: float, dt: float, rng: np.random.Generator,
                 axes: int = 3):
        p, c = flicker_design(b, tau_min, tau_max, dt)
        phi = np.exp(-p * dt)
        u = -np.expm1(-p * dt) / p / math.sqrt(dt)
        cov = 1.0 / (p[:, None] + p[None, :])       # stationary covariance of the branches, unit white input
        vals, vecs = np.linalg.eigh(cov)
        root = vecs * np.sqrt(np.clip(vals, 0.0, None))
        state = root @ rng.standard_normal((p.size, axes))
        super().__init__(phi, u, c * phi, float(np.dot(c, u)), state, rng)


class Quantizer:
    """Quantises increments to multiples of ``step`` carrying the remainder (an accumulating counter's output).

    The accumulated angle / velocity is rounded, so the increment error is the difference of two rounding errors:
    IEEE quantization noise with Q = step / sqrt(12) and Allan variance 3 Q^2 / tau^2.
    """

    def __init__(self, step: float, axes: int = 3):
        self.step = step
        self.residual = np.zeros(axes)

    def block(self, increments: np.ndarray) -> np.ndarray:
        from .kernels import quantize  # compiled: only a quantizing IMU starts numba

        out = np.empty_like(increments)
        quantize(np.ascontiguousarray(increments), self.step, self.residual, out)
        return out


def butter2_lowpass(cutoff_hz: float, dt: float) -> np.ndarray:
    """Second-order Butterworth low-pass at ``cutoff_hz`` for samples every ``dt`` s, bilinear transform with the
    cut-off pre-warped: one second-order section [b0, b1, b2, 1, a1, a2] (scipy's sos layout, unity DC gain).

    Closed form of H(s) = 1 / (s^2 + sqrt(2) s + 1) with s -> (1 - 1/z) / (K (1 + 1/z)), K = tan(pi f_c dt);
    equal to ``scipy.signal.butter(2, f_c, fs=1/dt, output="sos")`` to rounding, without importing scipy.signal
    (about 1 s of CPU at start-up).
    """
    k = math.tan(math.pi * cutoff_hz * dt)
    k2 = k * k
    norm = 1.0 + math.sqrt(2.0) * k + k2
    b0 = k2 / norm
    return np.array([b0, 2.0 * b0, b0, 1.0, 2.0 * (k2 - 1.0) / norm, (1.0 - math.sqrt(2.0) * k + k2) / norm])


class LowPass:
    """Second-order Butterworth low-pass at ``cutoff_hz`` (bilinear, pre-warped), started in steady state."""

    def __init__(self, cutoff_hz: float, dt: float):
        self.sos = butter2_lowpass(cutoff_hz, dt)
        self.filter = None

    def block(self, x: np.ndarray) -> np.ndarray:
        if self.filter is None:  # transposed direct form II as a state-space filter, at rest on the input x[0]
            b0, b1, b2, _, a1, a2 = self.sos
            a = np.array([[-a1, 1.0], [-a2, 0.0]])
            b = np.array([b1 - a1 * b0, b2 - a2 * b0])
            steady = np.linalg.solve(np.eye(2) - a, b)
            self.filter = FrameFilter(a, b, np.array([1.0, 0.0]), b0, steady[:, None] * x[:1])
        return self.filter.apply(np.asarray(x, dtype=float))
