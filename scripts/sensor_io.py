#!/usr/bin/env python3
"""Depth frames for the sensor calibration (scripts/fit_sensors.py): an
organized PCD (ascii, binary or binary_compressed) or a 16-bit depth PNG,
as a depth image in mm (0 = no measurement) with pinhole intrinsics.

    read_pcd_depth(path)  -> (depth_mm, K)   K = dict(fx, fy, cx, cy)
    read_png_depth(path, depth_scale, K) -> (depth_mm, K)
    read_bop_depth(scene_dir, im_id) -> (depth_mm, K) from scene_camera.json
    read_txt_depth(path, width, height, K) -> (depth_mm, K)
    read_frame(path, source) -> (depth_mm, K, luminance or None) as
        results/sensors/sources.json describes the frame

An organized PCD holds x, y, z per pixel (m; NaN where no depth). Its
intrinsics are recovered by least squares from x = (u - cx) z / fx and
y = (v - cy) z / fy over the valid pixels (OpenNI writes them so).
Needs numpy; PNGs also need PIL (python3-pil, pulled in by
python3-matplotlib)."""
import json
import os
import struct

import numpy as np


def lzf_decompress(data, out_len):
    """LZF (liblzf) decompression, as PCD's binary_compressed uses."""
    out = bytearray(out_len)
    i = o = 0
    n = len(data)
    while i < n:
        ctrl = data[i]
        i += 1
        if ctrl < 32:  # literal run of ctrl + 1 bytes
            length = ctrl + 1
            out[o:o + length] = data[i:i + length]
            i += length
            o += length
            continue
        length = ctrl >> 5
        ref = o - ((ctrl & 0x1F) << 8) - 1
        if length == 7:
            length += data[i]
            i += 1
        ref -= data[i]
        i += 1
        length += 2
        if ref < 0:
            raise ValueError("corrupt LZF stream")
        if ref + length <= o:
            out[o:o + length] = out[ref:ref + length]
        else:  # overlapping back reference: byte by byte
            for k in range(length):
                out[o + k] = out[ref + k]
        o += length
    if o != out_len:
        raise ValueError("LZF: %d bytes decoded, %d expected" % (o, out_len))
    return bytes(out)


def _pcd_header(f):
    header = {}
    while True:
        line = f.readline()
        if not line:
            raise ValueError("PCD without DATA line")
        text = line.decode("ascii", "replace").strip()
        if not text or text.startswith("#"):
            continue
        key, _, rest = text.partition(" ")
        header[key.upper()] = rest.split()
        if key.upper() == "DATA":
            return header


def _pcd_fields(header):
    names = header["FIELDS"]
    sizes = [int(s) for s in header["SIZE"]]
    types = header["TYPE"]
    counts = [int(c) for c in header.get("COUNT", ["1"] * len(names))]
    code = {("F", 4): "<f4", ("F", 8): "<f8", ("U", 1): "u1", ("U", 2): "<u2", ("U", 4): "<u4",
            ("I", 1): "i1", ("I", 2): "<i2", ("I", 4): "<i4"}
    return [(n, code[(t, s)], c) for n, s, t, c in zip(names, sizes, types, counts)]


def read_pcd_xyz(path, extra=()):
    """(x, y, z, *extra) arrays of shape (height, width) from an organized
    PCD (x, y, z in m); `extra` names further fields (e.g. "rgb", "rgba")."""
    with open(path, "rb") as f:
        header = _pcd_header(f)
        body = f.read()
    w, h = int(header["WIDTH"][0]), int(header["HEIGHT"][0])
    n = int(header["POINTS"][0])
    fields = _pcd_fields(header)
    kind = header["DATA"][0]
    cols = {}
    if kind == "ascii":
        rows = np.array([ln.split() for ln in body.decode().splitlines() if ln.strip()], dtype=np.float64)
        k = 0
        for name, _, c in fields:
            cols[name] = rows[:, k]
            k += c
    elif kind == "binary":
        dt = np.dtype([(name, t, (c,)) if c > 1 else (name, t) for name, t, c in fields])
        arr = np.frombuffer(body[:dt.itemsize * n], dtype=dt)
        cols = {name: arr[name] for name, _, _ in fields}
    elif kind == "binary_compressed":
        comp, raw = struct.unpack("<II", body[:8])
        data = lzf_decompress(body[8:8 + comp], raw)
        off = 0
        for name, t, c in fields:  # column-major: each field's array in turn
            size = np.dtype(t).itemsize * c * n
            cols[name] = np.frombuffer(data[off:off + size], dtype=t)
            off += size
    else:
        raise ValueError("unknown PCD DATA kind " + kind)
    xyz = tuple(np.asarray(cols[a], dtype=np.float64).reshape(h, w) for a in ("x", "y", "z"))
    return xyz + tuple(np.asarray(cols[a]).reshape(h, w) for a in extra)


def intrinsics_from_xyz(x, y, z):
    """fx, fy, cx, cy fitted to x/z = (u - cx)/fx, y/z = (v - cy)/fy."""
    h, w = z.shape
    v, u = np.mgrid[0:h, 0:w]
    ok = np.isfinite(z) & (z > 0) & np.isfinite(x) & np.isfinite(y)
    if ok.sum() < 10:
        raise ValueError("too few valid points to recover intrinsics")
    K = {}
    for coord, pix, f, c in ((x, u, "fx", "cx"), (y, v, "fy", "cy")):
        a = coord[ok] / z[ok]
        A = np.stack([a, np.ones_like(a)], axis=1)  # pix = f * a + c
        (slope, icpt), *_ = np.linalg.lstsq(A, pix[ok].astype(np.float64), rcond=None)
        K[f], K[c] = float(slope), float(icpt)
    return K


def pcd_luminance(path):
    """Luminance 0..255 of an organized PCD's rgb / rgba field (None without one)."""
    with open(path, "rb") as f:
        names = _pcd_header(f)["FIELDS"]
    field = next((n for n in ("rgba", "rgb") if n in names), None)
    if field is None:
        return None
    c = read_pcd_xyz(path, (field,))[3]
    c = np.ascontiguousarray(c).view(np.uint32) if c.dtype.itemsize == 4 else c.astype(np.uint32)
    r, g, b = (c >> 16) & 255, (c >> 8) & 255, c & 255
    return 0.299 * r + 0.587 * g + 0.114 * b


def read_pcd_depth(path, luminance=False):
    """(depth_mm, K) of an organized PCD (z in m, NaN = no depth); with
    luminance=True also the colour's luminance (or None)."""
    x, y, z = read_pcd_xyz(path)
    if z.shape[0] < 2:
        raise ValueError(path + " is not organized (height 1)")
    K = intrinsics_from_xyz(x, y, z)
    depth = np.where(np.isfinite(z) & (z > 0), z * 1000.0, 0.0)
    if luminance:
        return depth, K, pcd_luminance(path)
    return depth, K


def read_png_depth(path, depth_scale, K):
    """(depth_mm, K) of a 16-bit depth PNG: value * depth_scale = mm."""
    from PIL import Image
    a = np.array(Image.open(path)).astype(np.float64)
    return a * depth_scale, dict(K)


def read_txt_depth(path, width, height, K):
    """(depth_mm, K) of a depth image written as text, one value per line (mm,
    0 = no depth), row by row: how the Kinect v2 SDK's depth buffer
    (CopyFrameDataToArray) is dumped by a loop over it. The file holds no
    intrinsics; K is given."""
    with open(path) as f:
        vals = [ln.strip() for ln in f if ln.strip()]
    if len(vals) != width * height:
        raise ValueError("%s: %d values, %d x %d = %d expected" % (path, len(vals), width, height, width * height))
    depth = np.array(vals, dtype=np.float64).reshape(height, width)
    if not np.all(np.isfinite(depth)) or (depth < 0).any():
        raise ValueError("%s: negative or non-finite depth" % path)
    return depth, dict(K)


def read_frame(path, source):
    """(depth_mm, K, luminance or None) of a real frame listed in
    results/sensors/sources.json: `format` pcd (the default: an organized
    PCD, intrinsics recovered from it), txt (read_txt_depth with the entry's
    width, height and intrinsics) or png (a 16-bit depth PNG, value x the
    entry's depth_scale, default 1, = mm; the entry's intrinsics)."""
    fmt = source.get("format", "pcd")
    if fmt == "pcd":
        return read_pcd_depth(path, luminance=True)
    if fmt == "txt":
        depth, K = read_txt_depth(path, source["width"], source["height"], source["intrinsics"])
        return depth, K, None
    if fmt == "png":
        depth, K = read_png_depth(path, source.get("depth_scale", 1.0), source["intrinsics"])
        return depth, K, None
    raise ValueError("%s: unknown frame format %r" % (path, fmt))


def read_bop_depth(scene_dir, im_id):
    """(depth_mm, K) of image im_id of a BOP scene folder."""
    with open(os.path.join(scene_dir, "scene_camera.json")) as f:
        cam = json.load(f)[str(im_id)]
    k = cam["cam_K"]
    K = {"fx": k[0], "fy": k[4], "cx": k[2], "cy": k[5]}
    return read_png_depth(os.path.join(scene_dir, "depth", "%06d.png" % im_id), cam["depth_scale"], K)
