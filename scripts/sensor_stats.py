#!/usr/bin/env python3
"""Depth-sensor statistics per distance, measured the same way on real and
simulated frames (scripts/fit_sensors.py fits the sensor models to them).

From an organized depth image (mm, 0 = no measurement) and its intrinsics:
- noise: residual RMS of a least-squares plane z = a + b u + c v over each
  P x P patch (P = 7) that is fully valid and has no jump between
  neighbours above JUMP_REL * z + JUMP_MM; per depth bin the median (and
  quartiles) over the patches. Quantization steps are part of it, as they
  are part of a real sensor's noise.
- quantization: the gaps between consecutive distinct depth values of a
  frame inside a depth bin; per bin the median gap (frames with at least
  MIN_LEVELS distinct values), then the median over frames.
- missing data: per B x B block (B = 8) the median valid depth gives the
  block's distance; per bin the missing fraction of the blocks' pixels
  (blocks without any valid pixel are counted apart as `empty_blocks`).
  At edges: a pixel whose 7 x 7 window holds valid depths further apart
  than EDGE_REL * near + EDGE_MM is near an edge; per bin (of the near
  depth) the missing fraction of such pixels, and of the others.
- incidence: blocks with at least a quarter of their pixels valid and a
  plane through their 3D points (RMS distance under 0.01 z + 3 mm); angle
  between the block's viewing ray and the plane normal; per angle bin the
  missing fraction of those blocks' pixels.
- edge behaviour: along rows and columns, every three consecutive valid
  pixels a, m, b whose outer two differ by more than EDGE_REL * near +
  EDGE_MM; the fraction whose middle lies between them,
  0.15 < (m - a) / (b - a) < 0.85 (a flying or mixed pixel), per bin of the
  near depth, and the histogram of that position.
- dark surfaces (real frames with colour only): the missing fraction per
  luminance bin (0..255 in steps of 32) of the registered colour image.
Everything is accumulated over frames (Stats.add) and summarized per bin
(Stats.summary). Needs numpy."""
import numpy as np

P = 7                # noise patch size (px)
JUMP_REL, JUMP_MM = 0.03, 10.0   # a jump inside a noise patch rejects it
B = 8                # block size for missing data and incidence (px)
EDGE_R = 3           # edge window half size (7 x 7)
EDGE_REL, EDGE_MM = 0.10, 50.0   # a depth discontinuity
MIN_LEVELS = 5       # distinct depth values a frame needs in a bin for its quantization step
ANGLE_BINS = [0, 30, 45, 60, 70, 75, 80, 85, 90]


def depth_bins(lo=500, hi=4500, step=250):
    """[(lo, hi), ...] depth bins in mm."""
    return [(float(a), float(a + step)) for a in np.arange(lo, hi, step)]


def bin_index(z, bins):
    """Index of the bin of each depth (-1 outside)."""
    edges = np.array([b[0] for b in bins] + [bins[-1][1]])
    idx = np.searchsorted(edges, z, side="right") - 1
    idx[(z < edges[0]) | (z >= edges[-1])] = -1
    return idx


def _filter1d(a, r, axis, fn, fill):
    pad = [(0, 0), (0, 0)]
    pad[axis] = (r, r)
    p = np.pad(a, pad, constant_values=fill)
    win = np.lib.stride_tricks.sliding_window_view(p, 2 * r + 1, axis=axis)
    return fn(win, axis=-1)


def window_min_max(depth, r):
    """Min and max of the valid depths in each (2r+1)^2 window (inf / -inf if none)."""
    valid = depth > 0
    lo = np.where(valid, depth, np.inf)
    hi = np.where(valid, depth, -np.inf)
    for axis in (0, 1):
        lo = _filter1d(lo, r, axis, np.min, np.inf)
        hi = _filter1d(hi, r, axis, np.max, -np.inf)
    return lo, hi


def patch_noise(depth):
    """(mean depth, residual RMS) of the smooth, fully valid P x P patches."""
    h, w = depth.shape
    hp, wp = h // P, w // P
    tiles = depth[:hp * P, :wp * P].reshape(hp, P, wp, P).transpose(0, 2, 1, 3).reshape(-1, P * P)
    ok = np.all(tiles > 0, axis=1)
    t = tiles[ok]
    if len(t) == 0:
        return np.zeros(0), np.zeros(0)
    grid = t.reshape(-1, P, P)
    zmean = t.mean(axis=1)
    jump = np.maximum(np.abs(np.diff(grid, axis=1)).max(axis=(1, 2)), np.abs(np.diff(grid, axis=2)).max(axis=(1, 2)))
    smooth = jump <= JUMP_REL * zmean + JUMP_MM
    v, u = np.mgrid[0:P, 0:P]
    A = np.stack([np.ones(P * P), u.ravel(), v.ravel()], axis=1)
    coef = t[smooth] @ np.linalg.pinv(A).T
    resid = t[smooth] - coef @ A.T
    rms = np.sqrt((resid ** 2).sum(axis=1) / (P * P - 3))
    return zmean[smooth], rms


def quant_steps(depth, bins):
    """Per bin the median gap between consecutive distinct depths (NaN if too few)."""
    v = depth[depth > 0]
    idx = bin_index(v, bins)
    out = np.full(len(bins), np.nan)
    for i in range(len(bins)):
        levels = np.unique(v[idx == i])
        if len(levels) >= MIN_LEVELS:
            out[i] = float(np.median(np.diff(levels)))
    return out


def _blocks(a):
    h, w = a.shape
    hb, wb = h // B, w // B
    return a[:hb * B, :wb * B].reshape(hb, B, wb, B).transpose(0, 2, 1, 3).reshape(hb, wb, B * B)


def block_missing(depth):
    """(block depth, missing count, pixels) of blocks with a valid pixel; empty block count."""
    blk = _blocks(depth)
    valid = blk > 0
    nvalid = valid.sum(axis=2)
    has = nvalid > 0
    masked = np.where(valid, blk, np.nan)
    with np.errstate(all="ignore"):
        zb = np.nanmedian(masked[has], axis=1)
    return zb, (B * B - nvalid[has]), np.full(has.sum(), B * B), int((~has).sum())


def edge_missing(depth):
    """(near depth, missing?, at edge?) of pixels whose window has valid depth."""
    lo, hi = window_min_max(depth, EDGE_R)
    has = np.isfinite(lo)
    edge = (hi - lo) > EDGE_REL * lo + EDGE_MM
    return lo[has], (depth[has] <= 0), edge[has]


def backproject(depth, K):
    h, w = depth.shape
    v, u = np.mgrid[0:h, 0:w].astype(np.float64)
    x = (u - K["cx"]) / K["fx"] * depth
    y = (v - K["cy"]) / K["fy"] * depth
    return np.stack([x, y, depth], axis=-1)


def block_incidence(depth, K):
    """(incidence deg, missing count, pixels) of blocks with a plane fit."""
    pts = backproject(depth, K)
    valid = _blocks(depth) > 0
    P3 = np.stack([_blocks(pts[..., k]) for k in range(3)], axis=-1)  # hb, wb, B*B, 3
    n = valid.sum(axis=2)
    sel = n >= (B * B) // 4
    P3, valid, n = P3[sel], valid[sel], n[sel]
    wts = valid[..., None].astype(np.float64)
    mean = (P3 * wts).sum(axis=1) / n[:, None]
    d = (P3 - mean[:, None, :]) * wts
    cov = np.einsum("bki,bkj->bij", d, d) / n[:, None, None]
    evals, evecs = np.linalg.eigh(cov)
    normal = evecs[:, :, 0]
    rms = np.sqrt(np.maximum(evals[:, 0], 0))
    planar = rms < 0.01 * mean[:, 2] + 3.0
    ray = mean / np.linalg.norm(mean, axis=1, keepdims=True)
    cosang = np.abs((normal * ray).sum(axis=1))
    ang = np.degrees(np.arccos(np.clip(cosang, 0, 1)))
    return ang[planar], (B * B - n[planar]), np.full(planar.sum(), B * B)


def edge_triplets(depth):
    """(near depth, position t) of valid triplets a, m, b straddling a discontinuity."""
    near, pos = [], []
    for a, m, b in ((depth[:, :-2], depth[:, 1:-1], depth[:, 2:]), (depth[:-2, :], depth[1:-1, :], depth[2:, :])):
        ok = (a > 0) & (m > 0) & (b > 0)
        lo = np.minimum(a, b)
        jump = np.abs(b - a)
        sel = ok & (jump > EDGE_REL * lo + EDGE_MM)
        near.append(lo[sel])
        with np.errstate(divide="ignore", invalid="ignore"):
            pos.append(((m - a) / (b - a))[sel])
    return np.concatenate(near), np.concatenate(pos)


class Stats:
    """Statistics accumulated over frames, summarized per depth bin."""

    def __init__(self, bins=None):
        self.bins = bins or depth_bins()
        nb = len(self.bins)
        self.patches = [[] for _ in range(nb)]
        self.quant = [[] for _ in range(nb)]
        self.miss = np.zeros((nb, 2))       # missing, pixels
        self.edge = np.zeros((nb, 2))
        self.nonedge = np.zeros((nb, 2))
        self.inc = np.zeros((len(ANGLE_BINS) - 1, 2))
        self.fly = np.zeros((nb, 2))        # in-between, triplets
        self.pos_hist = np.zeros(10)
        self.lum = np.zeros((8, 2))         # missing, pixels per luminance bin
        self.empty_blocks = 0
        self.blocks = 0
        self.frames = 0

    def _acc(self, table, z, missing, total):
        idx = bin_index(np.asarray(z, dtype=np.float64), self.bins)
        ok = idx >= 0
        np.add.at(table[:, 0], idx[ok], np.asarray(missing, dtype=np.float64)[ok])
        np.add.at(table[:, 1], idx[ok], np.asarray(total, dtype=np.float64)[ok])

    def add(self, depth, K, luminance=None, geometry_only=False):
        """Adds a frame; geometry_only: noise and quantization only (a frame
        cropped by its publisher, whose missing pixels say nothing)."""
        depth = np.where(np.isfinite(depth) & (depth > 0), depth, 0.0).astype(np.float64)
        self.frames += 1
        zp, rms = patch_noise(depth)
        for i, r in zip(bin_index(zp, self.bins), rms):
            if i >= 0:
                self.patches[i].append(float(r))
        for i, q in enumerate(quant_steps(depth, self.bins)):
            if np.isfinite(q):
                self.quant[i].append(float(q))
        if geometry_only:
            return
        if luminance is not None:
            li = np.clip((luminance // 32).astype(int), 0, 7).ravel()
            np.add.at(self.lum[:, 0], li, (depth <= 0).ravel().astype(np.float64))
            np.add.at(self.lum[:, 1], li, 1.0)
        zb, miss, tot, empty = block_missing(depth)
        self._acc(self.miss, zb, miss, tot)
        self.empty_blocks += empty
        self.blocks += len(zb) + empty
        near, missing, at_edge = edge_missing(depth)
        self._acc(self.edge, near[at_edge], missing[at_edge], np.ones(at_edge.sum()))
        self._acc(self.nonedge, near[~at_edge], missing[~at_edge], np.ones((~at_edge).sum()))
        ang, miss, tot = block_incidence(depth, K)
        ai = np.clip(np.searchsorted(ANGLE_BINS, ang, side="right") - 1, 0, len(ANGLE_BINS) - 2)
        np.add.at(self.inc[:, 0], ai, miss)
        np.add.at(self.inc[:, 1], ai, tot)
        near, pos = edge_triplets(depth)
        self._acc(self.fly, near, (pos > 0.15) & (pos < 0.85), np.ones(len(pos)))
        self.pos_hist += np.histogram(np.clip(pos, 0, 1), bins=10, range=(0, 1))[0]

    def summary(self, min_count=30):
        """Per-bin numbers (None where fewer than min_count samples)."""
        def rate(table, n_min):
            return [round(m / t, 4) if t >= n_min else None for m, t in table]

        def med(lists, q=50, n_min=min_count):
            return [round(float(np.percentile(v, q)), 3) if len(v) >= n_min else None for v in lists]
        return {
            "frames": self.frames,
            "bins_mm": [list(b) for b in self.bins],
            "noise_mm": {"median": med(self.patches), "p25": med(self.patches, 25), "p75": med(self.patches, 75),
                         "patches": [len(v) for v in self.patches]},
            "quant_step_mm": {"median": med(self.quant, 50, 1), "frames": [len(v) for v in self.quant]},
            "missing": {"rate": rate(self.miss, 64 * min_count), "pixels": self.miss[:, 1].astype(int).tolist()},
            "empty_block_fraction": round(self.empty_blocks / max(1, self.blocks), 4),
            "edge_missing": {"rate": rate(self.edge, 64 * min_count), "pixels": self.edge[:, 1].astype(int).tolist()},
            "nonedge_missing": {"rate": rate(self.nonedge, 64 * min_count),
                                "pixels": self.nonedge[:, 1].astype(int).tolist()},
            "incidence": {"bins_deg": ANGLE_BINS, "missing_rate": rate(self.inc, 64 * 10),
                          "blocks": (self.inc[:, 1] / (B * B)).astype(int).tolist()},
            "flying": {"rate": rate(self.fly, min_count), "triplets": self.fly[:, 1].astype(int).tolist(),
                       "position_hist": self.pos_hist.astype(int).tolist()},
            "luminance_missing": {"bins": [[32 * i, 32 * i + 32] for i in range(8)],
                                  "rate": rate(self.lum, 500), "pixels": self.lum[:, 1].astype(int).tolist()},
            "pooled": {name: round(t[:, 0].sum() / t[:, 1].sum(), 4) if t[:, 1].sum() > 0 else None
                       for name, t in (("missing", self.miss), ("edge_missing", self.edge),
                                       ("nonedge_missing", self.nonedge), ("flying", self.fly))},
        }
