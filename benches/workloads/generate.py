#!/usr/bin/env python3
"""Builds the workload suite: glTF binary scenes of the kinds people render, made from the
public models the project already reads (the reference scenes and the real-world test files of
the shared folder), drawn by the reference scenes' rules (Lambert, a camera, a resolution).

Usage: benches/workloads/generate.py OUT_DIR [--shared DIR]

OUT_DIR receives one `.glb` per workload and `workloads.json` (each workload's triangles, draws,
textures and what it stands for). Nothing here is committed: the files are rebuilt from the
sources, the same bytes every time (no randomness beyond a fixed-seed generator). Standard
library only, so it runs wherever Python 3.8+ does.
"""

import argparse
import json
import math
import os
import struct
import sys
import zlib
from array import array

# --- reading glTF sources ---------------------------------------------------------------------

COMPONENTS = {5120: ("b", 1), 5121: ("B", 1), 5122: ("h", 2), 5123: ("H", 2), 5125: ("I", 4), 5126: ("f", 4)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
NORMALIZE = {"b": 127.0, "B": 255.0, "h": 32767.0, "H": 65535.0}


class Source:
    """A glTF file (`.glb` or `.gltf` with files beside it) opened for reading."""

    def __init__(self, path):
        self.path = path
        data = open(path, "rb").read()
        self.buffers = []
        if data[:4] == b"glTF":
            json_length = struct.unpack_from("<I", data, 12)[0]
            self.json = json.loads(data[20 : 20 + json_length])
            offset = 20 + json_length
            if offset < len(data):
                bin_length = struct.unpack_from("<I", data, offset)[0]
                self.buffers.append(data[offset + 8 : offset + 8 + bin_length])
        else:
            self.json = json.loads(data)
            folder = os.path.dirname(path)
            for buffer in self.json.get("buffers", []):
                self.buffers.append(open(os.path.join(folder, buffer["uri"]), "rb").read())

    def view_bytes(self, index):
        view = self.json["bufferViews"][index]
        start = view.get("byteOffset", 0)
        return self.buffers[view["buffer"]][start : start + view["byteLength"]]

    def accessor(self, index):
        """The accessor's elements as tuples of floats (normalized integers scaled to [0, 1])."""
        acc = self.json["accessors"][index]
        if "sparse" in acc or "bufferView" not in acc:
            raise SystemExit(f"generate: {self.path}: accessor {index} is sparse or empty")
        code, size = COMPONENTS[acc["componentType"]]
        width = WIDTH[acc["type"]]
        view = self.json["bufferViews"][acc["bufferView"]]
        raw = self.view_bytes(acc["bufferView"])
        start = acc.get("byteOffset", 0)
        stride = view.get("byteStride", size * width)
        count = acc["count"]
        if stride == size * width:
            flat = array(code, raw[start : start + count * stride])
        else:
            flat = array(code)
            for i in range(count):
                flat.frombytes(raw[start + i * stride : start + i * stride + size * width])
        if acc.get("normalized") and code in NORMALIZE:
            scale = NORMALIZE[code]
            flat = array("f", (max(v / scale, -1.0) for v in flat))
        return [tuple(flat[i * width : (i + 1) * width]) for i in range(count)]

    def image_bytes(self, index):
        image = self.json["images"][index]
        if "bufferView" in image:
            return self.view_bytes(image["bufferView"]), image["mimeType"]
        path = os.path.join(os.path.dirname(self.path), image["uri"])
        mime = "image/png" if path.lower().endswith(".png") else "image/jpeg"
        return open(path, "rb").read(), mime

    def meshes(self):
        """Every primitive of the default scene in world space: dicts with positions, normals,
        uvs (or None), indices and the material index."""
        out = []
        scene = self.json["scenes"][self.json.get("scene", 0)]

        def visit(node_index, parent):
            node = self.json["nodes"][node_index]
            world = mat_mul(parent, node_matrix(node))
            if "mesh" in node:
                normal_matrix = inverse_transpose3(world)
                for prim in self.json["meshes"][node["mesh"]]["primitives"]:
                    if prim.get("mode", 4) != 4:
                        continue
                    attrs = prim["attributes"]
                    positions = [transform_point(world, p) for p in self.accessor(attrs["POSITION"])]
                    normals = None
                    if "NORMAL" in attrs:
                        normals = [normalize(mat3_vec(normal_matrix, n)) for n in self.accessor(attrs["NORMAL"])]
                    uvs = self.accessor(attrs["TEXCOORD_0"]) if "TEXCOORD_0" in attrs else None
                    if "indices" in prim:
                        indices = [i[0] for i in self.accessor(prim["indices"])]
                    else:
                        indices = list(range(len(positions)))
                    if det3(world) < 0:  # a mirrored node: keep the faces counter-clockwise
                        for t in range(0, len(indices) - 2, 3):
                            indices[t + 1], indices[t + 2] = indices[t + 2], indices[t + 1]
                    out.append(
                        {"positions": positions, "normals": normals, "uvs": uvs, "indices": indices,
                         "material": prim.get("material")}
                    )
            for child in node.get("children", []):
                visit(child, world)

        for root in scene["nodes"]:
            visit(root, IDENTITY)
        return out


# --- small linear algebra (column-major 4x4 as glTF stores them) --------------------------------

IDENTITY = [1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0, 0, 0, 0, 0, 1.0]


def mat_mul(a, b):
    return [sum(a[k * 4 + r] * b[c * 4 + k] for k in range(4)) for c in range(4) for r in range(4)]


def node_matrix(node):
    if "matrix" in node:
        return [float(v) for v in node["matrix"]]
    tx, ty, tz = node.get("translation", [0, 0, 0])
    qx, qy, qz, qw = node.get("rotation", [0, 0, 0, 1])
    sx, sy, sz = node.get("scale", [1, 1, 1])
    r = [
        1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy + qz * qw), 2 * (qx * qz - qy * qw),
        2 * (qx * qy - qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz + qx * qw),
        2 * (qx * qz + qy * qw), 2 * (qy * qz - qx * qw), 1 - 2 * (qx * qx + qy * qy),
    ]
    return [r[0] * sx, r[1] * sx, r[2] * sx, 0, r[3] * sy, r[4] * sy, r[5] * sy, 0,
            r[6] * sz, r[7] * sz, r[8] * sz, 0, tx, ty, tz, 1]


def transform_point(m, p):
    x, y, z = p[0], p[1], p[2]
    return (m[0] * x + m[4] * y + m[8] * z + m[12], m[1] * x + m[5] * y + m[9] * z + m[13],
            m[2] * x + m[6] * y + m[10] * z + m[14])


def det3(m):
    return (m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2])
            + m[8] * (m[1] * m[6] - m[5] * m[2]))


def inverse_transpose3(m):
    """Cofactor matrix of the upper 3x3 (the inverse transpose up to a positive scale, which the
    normalisation removes; the sign of the determinant is kept)."""
    a = [[m[0], m[4], m[8]], [m[1], m[5], m[9]], [m[2], m[6], m[10]]]
    d = det3(m)
    sign = 1.0 if d >= 0 else -1.0
    cof = [[0.0] * 3 for _ in range(3)]
    for r in range(3):
        for c in range(3):
            r1, r2 = [i for i in range(3) if i != r]
            c1, c2 = [i for i in range(3) if i != c]
            cof[r][c] = ((-1) ** (r + c)) * (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) * sign
    return cof


def mat3_vec(m, v):
    return tuple(m[r][0] * v[0] + m[r][1] * v[1] + m[r][2] * v[2] for r in range(3))


def normalize(v):
    length = math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) or 1.0
    return (v[0] / length, v[1] / length, v[2] / length)


def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def look_at(eye, target, up=(0.0, 1.0, 0.0)):
    """The world matrix of a camera node at `eye` looking at `target` (glTF cameras look
    along their -Z)."""
    z = normalize(sub(eye, target))
    x = normalize(cross(up, z))
    y = cross(z, x)
    return [x[0], x[1], x[2], 0, y[0], y[1], y[2], 0, z[0], z[1], z[2], 0, eye[0], eye[1], eye[2], 1]


def bounds(meshes):
    lo = [math.inf] * 3
    hi = [-math.inf] * 3
    for mesh in meshes:
        for p in mesh["positions"]:
            for k in range(3):
                lo[k] = min(lo[k], p[k])
                hi[k] = max(hi[k], p[k])
    return lo, hi


class Random:
    """A fixed-seed linear congruential generator: the same workloads on every machine."""

    def __init__(self, seed):
        self.state = seed

    def uniform(self, lo=0.0, hi=1.0):
        self.state = (self.state * 6364136223846793005 + 1442695040888963407) % (1 << 64)
        return lo + (hi - lo) * ((self.state >> 11) / float(1 << 53))


# --- geometry ---------------------------------------------------------------------------------


def subdivide(mesh):
    """Splits every triangle into four at its edge midpoints (normals renormalised, uvs
    interpolated): the same surface with four times the triangles."""
    positions = list(mesh["positions"])
    normals = list(mesh["normals"]) if mesh["normals"] else None
    uvs = list(mesh["uvs"]) if mesh["uvs"] else None
    midpoints = {}

    def midpoint(a, b):
        key = (a, b) if a < b else (b, a)
        found = midpoints.get(key)
        if found is not None:
            return found
        pa, pb = positions[a], positions[b]
        positions.append(((pa[0] + pb[0]) / 2, (pa[1] + pb[1]) / 2, (pa[2] + pb[2]) / 2))
        if normals is not None:
            na, nb = normals[a], normals[b]
            normals.append(normalize((na[0] + nb[0], na[1] + nb[1], na[2] + nb[2])))
        if uvs is not None:
            ua, ub = uvs[a], uvs[b]
            uvs.append(((ua[0] + ub[0]) / 2, (ua[1] + ub[1]) / 2))
        midpoints[key] = len(positions) - 1
        return midpoints[key]

    old = mesh["indices"]
    indices = []
    for t in range(0, len(old) - 2, 3):
        a, b, c = old[t], old[t + 1], old[t + 2]
        ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
        indices += [a, ab, ca, ab, b, bc, ca, bc, c, ab, bc, ca]
    return dict(mesh, positions=positions, normals=normals, uvs=uvs, indices=indices)


def split(mesh, triangles_per_part):
    """Cuts a mesh into parts of at most `triangles_per_part` triangles, each with only the
    vertices it uses: what CAD exporters write, one small primitive per face or part."""
    parts = []
    old = mesh["indices"]
    step = 3 * triangles_per_part
    for start in range(0, len(old), step):
        remap = {}
        indices = []
        for i in old[start : start + step]:
            if i not in remap:
                remap[i] = len(remap)
            indices.append(remap[i])
        order = sorted(remap, key=remap.get)
        parts.append(dict(
            mesh,
            positions=[mesh["positions"][i] for i in order],
            normals=[mesh["normals"][i] for i in order] if mesh["normals"] else None,
            uvs=[mesh["uvs"][i] for i in order] if mesh["uvs"] else None,
            indices=indices,
        ))
    return parts


def translate(mesh, offset):
    return dict(mesh, positions=[(p[0] + offset[0], p[1] + offset[1], p[2] + offset[2]) for p in mesh["positions"]])


def box(lo, hi, uv_scale=(1.0, 1.0)):
    """An axis-aligned box, outward faces counter-clockwise, uvs repeating `uv_scale` times
    per unit of length."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    faces = [
        ((0, 0, 1), [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (x1 - x0, y1 - y0)),
        ((0, 0, -1), [(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)], (x1 - x0, y1 - y0)),
        ((1, 0, 0), [(x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)], (z1 - z0, y1 - y0)),
        ((-1, 0, 0), [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)], (z1 - z0, y1 - y0)),
        ((0, 1, 0), [(x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0)], (x1 - x0, z1 - z0)),
        ((0, -1, 0), [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (x1 - x0, z1 - z0)),
    ]
    return quads(faces, uv_scale)


def quads(faces, uv_scale=(1.0, 1.0)):
    positions, normals, uvs, indices = [], [], [], []
    for normal, corners, (w, h) in faces:
        base = len(positions)
        positions += corners
        normals += [normal] * 4
        su, sv = w * uv_scale[0], h * uv_scale[1]
        uvs += [(0.0, sv), (su, sv), (su, 0.0), (0.0, 0.0)]
        indices += [base, base + 1, base + 2, base, base + 2, base + 3]
    return {"positions": positions, "normals": normals, "uvs": uvs, "indices": indices}


def cylinder(center, radius, height, segments=24):
    """An upright cylinder with caps: 4 × `segments` triangles (96 for 24 segments)."""
    cx, cy, cz = center
    positions, normals, uvs, indices = [], [], [], []
    for s in range(segments + 1):
        a = 2 * math.pi * s / segments
        n = (math.cos(a), 0.0, -math.sin(a))
        for y, v in ((cy, 1.0), (cy + height, 0.0)):
            positions.append((cx + radius * n[0], y, cz + radius * n[2]))
            normals.append(n)
            uvs.append((s / segments * 2.0, v * height / radius / 4))
    for s in range(segments):
        a, b = 2 * s, 2 * s + 2
        indices += [a, b, b + 1, a, b + 1, a + 1]
    for y, ny in ((cy + height, 1.0), (cy, -1.0)):
        centre = len(positions)
        positions.append((cx, y, cz))
        normals.append((0.0, ny, 0.0))
        uvs.append((0.5, 0.5))
        for s in range(segments + 1):
            a = 2 * math.pi * s / segments
            positions.append((cx + radius * math.cos(a), y, cz - radius * math.sin(a)))
            normals.append((0.0, ny, 0.0))
            uvs.append((0.5 + 0.5 * math.cos(a), 0.5 + 0.5 * math.sin(a)))
        for s in range(segments):
            if ny > 0:
                indices += [centre, centre + 1 + s, centre + 2 + s]
            else:
                indices += [centre, centre + 2 + s, centre + 1 + s]
    return {"positions": positions, "normals": normals, "uvs": uvs, "indices": indices}


def billboard(center, width, height, facing):
    """A vertical quad centred on `center`, facing the direction `facing` (in the xz plane)."""
    f = normalize((facing[0], 0.0, facing[2]))
    right = (f[2], 0.0, -f[0])
    hw, hh = width / 2, height / 2
    cx, cy, cz = center
    corners = [
        (cx - right[0] * hw, cy - hh, cz - right[2] * hw),
        (cx + right[0] * hw, cy - hh, cz + right[2] * hw),
        (cx + right[0] * hw, cy + hh, cz + right[2] * hw),
        (cx - right[0] * hw, cy + hh, cz - right[2] * hw),
    ]
    mesh = quads([(f, corners, (1.0, 1.0))])
    return mesh


# --- procedural RGBA textures -------------------------------------------------------------------


def png_rgba(width, height, pixel):
    """A PNG (8-bit RGBA) of `pixel(x, y) -> (r, g, b, a)` in 0..255."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)
        for x in range(width):
            rows += bytes(pixel(x, y))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    header = struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(bytes(rows), 9))
            + chunk(b"IEND", b""))


def smoke_texture(size=256):
    """A soft round puff: alpha falls from 0.6 at the centre to 0 at the rim."""
    def pixel(x, y):
        dx, dy = (x + 0.5) / size * 2 - 1, (y + 0.5) / size * 2 - 1
        r = math.sqrt(dx * dx + dy * dy)
        a = max(0.0, 1.0 - r) ** 1.5 * 0.6
        shade = 200 + int(40 * math.sin(7 * dx) * math.cos(5 * dy))
        return (shade, shade - 10, shade - 25, int(a * 255 + 0.5))
    return png_rgba(size, size, pixel)


def leaves_texture(size=512, seed=1):
    """Leaf shapes on transparency, for alpha-masked foliage (alpha 0 or 255)."""
    rng = Random(seed)
    leaves = [(rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9), rng.uniform(0.04, 0.12), rng.uniform(0, math.pi))
              for _ in range(40)]

    def pixel(x, y):
        u, v = (x + 0.5) / size, (y + 0.5) / size
        for cx, cy, r, angle in leaves:
            du, dv = u - cx, v - cy
            a = du * math.cos(angle) + dv * math.sin(angle)
            b = -du * math.sin(angle) + dv * math.cos(angle)
            if (a / r) ** 2 + (b / (r * 0.4)) ** 2 < 1.0:
                green = 90 + int(60 * (a / r))
                return (40, green, 30, 255)
        return (0, 0, 0, 0)
    return png_rgba(size, size, pixel)


# --- writing glTF binaries ----------------------------------------------------------------------


class Builder:
    """Collects meshes, materials and textures and writes one reference-rule `.glb`."""

    def __init__(self, resolution, clear_color=(0.05, 0.05, 0.08, 1.0)):
        self.resolution = resolution
        self.clear_color = clear_color
        self.bin = bytearray()
        self.json = {
            "asset": {"version": "2.0", "generator": "kantele benches/workloads/generate.py"},
            "buffers": [], "bufferViews": [], "accessors": [], "meshes": [], "nodes": [],
            "materials": [], "textures": [], "images": [], "samplers": [
                {"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
        }
        self.image_index = {}
        self.triangles = 0
        self.draws = 0

    def _view(self, data, target=None):
        while len(self.bin) % 4:
            self.bin.append(0)
        view = {"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)}
        if target:
            view["target"] = target
        self.bin += data
        self.json["bufferViews"].append(view)
        return len(self.json["bufferViews"]) - 1

    def _accessor(self, values, kind, component, with_bounds=False):
        width = WIDTH[kind]
        code = COMPONENTS[component][0]
        flat = array(code)
        for v in values:
            if width == 1:
                flat.append(v)
            else:
                flat.extend(v)
        if sys.byteorder != "little":
            flat.byteswap()
        target = 34963 if kind == "SCALAR" else 34962
        acc = {"bufferView": self._view(flat.tobytes(), target), "componentType": component,
               "count": len(values), "type": kind}
        if with_bounds:
            acc["min"] = [min(v[k] for v in values) for k in range(width)]
            acc["max"] = [max(v[k] for v in values) for k in range(width)]
        self.json["accessors"].append(acc)
        return len(self.json["accessors"]) - 1

    def texture(self, data, mime):
        """A texture of an encoded image (each distinct image stored once)."""
        key = zlib.crc32(data), len(data)
        if key not in self.image_index:
            self.json["images"].append({"bufferView": self._view(data), "mimeType": mime})
            self.json["textures"].append({"source": len(self.json["images"]) - 1, "sampler": 0})
            self.image_index[key] = len(self.json["textures"]) - 1
        return self.image_index[key]

    def material(self, color=(0.8, 0.8, 0.8, 1.0), texture=None, alpha_mode="OPAQUE", double_sided=False):
        pbr = {"baseColorFactor": list(color), "metallicFactor": 0.0}
        if texture is not None:
            pbr["baseColorTexture"] = {"index": texture}
        material = {"pbrMetallicRoughness": pbr}
        if alpha_mode != "OPAQUE":
            material["alphaMode"] = alpha_mode
        if alpha_mode == "MASK":
            material["alphaCutoff"] = 0.5
        if double_sided:
            material["doubleSided"] = True
        self.json["materials"].append(material)
        return len(self.json["materials"]) - 1

    def mesh(self, mesh, material, colors=None):
        """One primitive (one draw) in a node of its own."""
        attributes = {"POSITION": self._accessor(mesh["positions"], "VEC3", 5126, with_bounds=True)}
        if mesh.get("normals"):
            attributes["NORMAL"] = self._accessor(mesh["normals"], "VEC3", 5126)
        if mesh.get("uvs"):
            attributes["TEXCOORD_0"] = self._accessor(mesh["uvs"], "VEC2", 5126)
        if colors:
            attributes["COLOR_0"] = self._accessor(colors, "VEC3", 5126)
        index_type = 5123 if len(mesh["positions"]) < 65536 else 5125
        primitive = {"attributes": attributes, "indices": self._accessor(mesh["indices"], "SCALAR", index_type),
                     "material": material}
        self.json["meshes"].append({"primitives": [primitive]})
        self.json["nodes"].append({"mesh": len(self.json["meshes"]) - 1})
        self.triangles += len(mesh["indices"]) // 3
        self.draws += 1

    def camera(self, eye, target, yfov_degrees=45.0, znear=0.05, zfar=1000.0, up=(0.0, 1.0, 0.0)):
        width, height = self.resolution
        self.json["cameras"] = [{"type": "perspective", "perspective": {
            "yfov": math.radians(yfov_degrees), "aspectRatio": width / height, "znear": znear, "zfar": zfar}}]
        self.json["nodes"].insert(0, {"camera": 0, "matrix": look_at(eye, target, up)})

    def write(self, path):
        for key in ("textures", "images", "materials"):
            if not self.json[key]:
                del self.json[key]
        if "textures" not in self.json:
            del self.json["samplers"]
        self.json["buffers"] = [{"byteLength": len(self.bin)}]
        self.json["scenes"] = [{"nodes": list(range(len(self.json["nodes"]))), "extras": {
            "resolution": list(self.resolution), "clear_color": list(self.clear_color), "ambient": 0.1}}]
        self.json["scene"] = 0
        text = json.dumps(self.json, separators=(",", ":")).encode()
        text += b" " * (-len(text) % 4)
        binary = bytes(self.bin) + b"\0" * (-len(self.bin) % 4)
        total = 12 + 8 + len(text) + 8 + len(binary)
        with open(path + ".part", "wb") as f:
            f.write(struct.pack("<III", 0x46546C67, 2, total))
            f.write(struct.pack("<II", len(text), 0x4E4F534A) + text)
            f.write(struct.pack("<II", len(binary), 0x004E4942) + binary)
        os.replace(path + ".part", path)


def frame(lo, hi, direction, yfov_degrees, fill=1.0):
    """An eye position looking along `direction` at the box's centre, at the distance where its
    bounding sphere spans `fill` of the picture's height."""
    centre = tuple((lo[k] + hi[k]) / 2 for k in range(3))
    radius = math.sqrt(sum((hi[k] - lo[k]) ** 2 for k in range(3))) / 2
    distance = radius / math.tan(math.radians(yfov_degrees) / 2) / fill
    d = normalize(direction)
    return tuple(centre[k] - d[k] * distance for k in range(3)), centre, distance


# --- the workloads ------------------------------------------------------------------------------


def texture_pool(shared):
    """Encoded images of the shared real-world files, larger ones first, in a fixed order."""
    realworld = os.path.join(shared, "realworld")
    found = []
    for folder, _, files in sorted(os.walk(realworld)):
        if "screenshot" in folder:
            continue
        for name in sorted(files):
            path = os.path.join(folder, name)
            lower = name.lower()
            if lower.endswith((".png", ".jpg", ".jpeg")):
                data = open(path, "rb").read()
                found.append((data, "image/png" if lower.endswith(".png") else "image/jpeg"))
            elif lower.endswith(".glb"):
                source = Source(path)
                for i in range(len(source.json.get("images", []))):
                    found.append(source.image_bytes(i))
    found = [f for f in found if len(f[0]) >= 20000]
    found.sort(key=lambda f: -len(f[0]))
    return found


def city(shared, out):
    """A city block seen from above at an angle: 166 textured buildings on a textured ground
    (167 draws, 20 textures), 1920×1080."""
    pool = texture_pool(shared)[:20]
    b = Builder((1920, 1080))
    textures = [b.texture(*image) for image in pool]
    materials = [b.material(texture=t) for t in textures]
    rng = Random(7)
    b.mesh(box((-70, -1, -70), (70, 0, 70), (0.1, 0.1)), materials[0])
    placed = 0
    for gx in range(13):
        for gz in range(13):
            if placed == 166:
                break
            x, z = (gx - 6) * 10.0, (gz - 6) * 10.0
            w, d = rng.uniform(3.0, 4.5), rng.uniform(3.0, 4.5)
            h = rng.uniform(4.0, 28.0)
            b.mesh(box((x - w, 0, z - d), (x + w, h, z + d), (0.25, 0.25)), materials[1 + placed % 19])
            placed += 1
    b.camera((95.0, 70.0, 110.0), (0.0, 4.0, 0.0), yfov_degrees=45.0, znear=1.0, zfar=500.0)
    return b


def billboards(shared, out):
    """240 alpha-blended textured billboards (about 25 layers over each pixel) in front of a
    textured wall, 1920×1080: particles, foliage cards, decals."""
    pool = texture_pool(shared)
    b = Builder((1920, 1080))
    wall = b.material(texture=b.texture(*pool[0]))
    b.mesh(quads([((0, 0, 1), [(-20, -12, 0), (20, -12, 0), (20, 12, 0), (-20, 12, 0)], (40, 24))], (0.1, 0.1)), wall)
    smoke = b.texture(smoke_texture(), "image/png")
    tints = [b.material(color=c, texture=smoke, alpha_mode="BLEND", double_sided=True)
             for c in ((1, 1, 1, 1), (1.0, 0.85, 0.7, 1), (0.7, 0.8, 1.0, 1), (0.85, 1.0, 0.8, 1))]
    rng = Random(11)
    for i in range(240):
        z = 1.0 + 14.0 * i / 240
        scale = (25.0 - z) / 25.0
        x, y = rng.uniform(-11, 11) * scale, rng.uniform(-6, 6) * scale
        size = rng.uniform(9.0, 13.0) * scale
        b.mesh(billboard((x, y, z), size, size, (0, 0, 1)), tints[i % len(tints)])
    b.camera((0.0, 0.0, 25.0), (0.0, 0.0, 0.0), yfov_degrees=50.0, znear=0.5, zfar=100.0)
    return b


def closeup_4k(shared, out):
    """A textured model (the water bottle, subdivided once: 18 k triangles) with its 2048²
    base-colour texture, its label filling a 3840×2160 frame."""
    path = os.path.join(shared, "realworld", "pbr", "SpecGlossVsMetalRough", "SpecGlossVsMetalRough.gltf")
    source = Source(path)
    bottle = [m for m in source.meshes() if m["material"] == 1][0]
    material = source.json["materials"][1]["pbrMetallicRoughness"]["baseColorTexture"]["index"]
    image = source.json["textures"][material]["source"]
    b = Builder((3840, 2160))
    b.mesh(subdivide(bottle), b.material(color=(1, 1, 1, 1), texture=b.texture(*source.image_bytes(image))))
    lo, hi = bounds([bottle])
    centre = tuple((lo[k] + hi[k]) / 2 for k in range(3))
    # The bottle's label faces -X in the world: look at it from there.
    eye = (centre[0] - 0.16, centre[1] + 0.01, centre[2])
    b.camera(eye, centre, yfov_degrees=35.0, znear=0.01, zfar=10.0)
    return b


def interior(shared, out):
    """A two-storey colonnaded courtyard seen from inside: floors, walls, columns, beams and
    alpha-masked plants; 287 draws, 24 textures (3 of them masked foliage), 1920×1080."""
    pool = texture_pool(shared)[:21]
    b = Builder((1920, 1080))
    solid = [b.material(texture=b.texture(*image)) for image in pool]
    leaves = [b.material(texture=b.texture(leaves_texture(seed=s), "image/png"), alpha_mode="MASK", double_sided=True)
              for s in (1, 2, 3)]
    # Floor, ceiling and walls (the box's inner faces: its faces turned inside out).
    room = box((-20, 0, -8), (20, 14, 8), (0.25, 0.25))
    room["indices"] = [room["indices"][i + k] for i in range(0, len(room["indices"]), 3) for k in (0, 2, 1)]
    room["normals"] = [(-n[0], -n[1], -n[2]) for n in room["normals"]]
    b.mesh(room, solid[0])
    draws = 1
    rng = Random(5)
    # Two storeys of colonnades on both long sides: base, shaft and capital per column.
    for storey, y in enumerate((0.0, 7.0)):
        for side in (-6.0, 6.0):
            for i in range(20):
                x = -19.0 + 2.0 * i
                b.mesh(box((x - 0.45, y, side - 0.45), (x + 0.45, y + 0.4, side + 0.45), (1, 1)), solid[1 + storey])
                b.mesh(cylinder((x, y + 0.4, side), 0.3, 5.6), solid[3 + storey])
                b.mesh(box((x - 0.5, y + 6.0, side - 0.5), (x + 0.5, y + 6.5, side + 0.5), (1, 1)), solid[5 + storey])
                draws += 3
    # Beams between the columns and the gallery floor.
    for side in (-6.0, 6.0):
        for i in range(10):
            x0 = -19.0 + 4.0 * i
            b.mesh(box((x0 - 0.5, 6.5, side - 0.4), (x0 + 3.5, 7.0, side + 0.4), (0.5, 0.5)), solid[7 + i % 6])
            draws += 1
        b.mesh(box((-20, 6.9, side - 2.0 if side < 0 else side), (20, 7.0, side if side < 0 else side + 2.0),
                   (0.25, 0.25)), solid[13])
        draws += 1
    # Banners hanging from the gallery.
    for i in range(20):
        x = -18.0 + 2.0 * i
        side = -5.5 if i % 2 else 5.5
        b.mesh(billboard((x, 5.0, side), 1.4, 3.0, (0, 0, 1 if side < 0 else -1)), solid[14 + i % 7])
        draws += 1
    # Plants: crossed alpha-masked cards in pots along the middle.
    while draws < 287:
        x, z = rng.uniform(-18, 18), rng.uniform(-4, 4)
        angle = rng.uniform(0, math.pi)
        size = rng.uniform(2.5, 4.5)
        b.mesh(billboard((x, size / 2, z), size, size, (math.cos(angle), 0, math.sin(angle))), leaves[draws % 3])
        draws += 1
    b.camera((-17.5, 2.2, 4.5), (6.0, 3.5, -1.5), yfov_degrees=60.0, znear=0.05, zfar=100.0)
    return b


def statue(shared):
    source = Source(os.path.join(shared, "scenes", "paper-c5-statue.glb"))
    return source.meshes()[0]


def vertex_colors(shared, out):
    """A 100 k-triangle scan coloured per vertex (no texture), filling a 1920×1080 frame."""
    mesh = statue(shared)
    lo, hi = bounds([mesh])
    colors = []
    for p, n in zip(mesh["positions"], mesh["normals"]):
        t = [(p[k] - lo[k]) / ((hi[k] - lo[k]) or 1.0) for k in range(3)]
        colors.append((0.3 + 0.6 * t[1], 0.3 + 0.5 * abs(n[0]), 0.9 - 0.6 * t[1]))
    b = Builder((1920, 1080))
    b.mesh(mesh, b.material(color=(1, 1, 1, 1)), colors=colors)
    eye, centre, _ = frame(lo, hi, (0.3, -0.1, -1.0), 40.0, fill=1.8)
    b.camera(eye, centre, yfov_degrees=40.0, znear=0.01, zfar=1000.0)
    return b


def engine_meshes(shared):
    return Source(os.path.join(shared, "realworld", "2CylinderEngine", "2CylinderEngine.glb")).meshes()


ENGINE_COLORS = [(0.75, 0.75, 0.78, 1), (0.55, 0.6, 0.7, 1), (0.8, 0.55, 0.3, 1), (0.4, 0.45, 0.4, 1),
                 (0.85, 0.8, 0.6, 1), (0.6, 0.3, 0.3, 1)]


def cad_assembly(shared, out):
    """Two engines cut into parts of at most 128 triangles each, as CAD exporters write them
    (about 2 000 small draws), 1920×1080."""
    parts = engine_meshes(shared)
    lo, hi = bounds(parts)
    width = hi[0] - lo[0]
    b = Builder((1920, 1080))
    materials = [b.material(color=c) for c in ENGINE_COLORS]
    for copy in range(2):
        offset = ((copy - 0.5) * width * 1.05, 0.0, 0.0)
        for k, part in enumerate(parts):
            for piece in split(translate(part, offset), 128):
                b.mesh(piece, materials[k % len(materials)])
    all_lo = (lo[0] - width * 0.525, lo[1], lo[2])
    all_hi = (hi[0] + width * 0.525, hi[1], hi[2])
    eye, centre, _ = frame(all_lo, all_hi, (-0.4, -0.5, -1.0), 40.0, fill=2.0)
    b.camera(eye, centre, yfov_degrees=40.0, znear=1.0, zfar=10000.0)
    return b


def cad_thumbnail(shared, out):
    """The engine as its file holds it (121 k triangles in 115 draws) in a 256×256 thumbnail."""
    parts = engine_meshes(shared)
    lo, hi = bounds(parts)
    b = Builder((256, 256))
    materials = [b.material(color=c) for c in ENGINE_COLORS]
    for k, part in enumerate(parts):
        b.mesh(part, materials[k % len(materials)])
    eye, centre, _ = frame(lo, hi, (-0.4, -0.5, -1.0), 40.0, fill=1.1)
    b.camera(eye, centre, yfov_degrees=40.0, znear=1.0, zfar=10000.0)
    return b


def scan(fill):
    def build(shared, out):
        mesh = subdivide(subdivide(statue(shared)))
        lo, hi = bounds([mesh])
        b = Builder((1920, 1080))
        b.mesh(mesh, b.material(color=(0.8, 0.78, 0.72, 1)))
        eye, centre, _ = frame(lo, hi, (0.3, -0.1, -1.0), 40.0, fill=fill)
        b.camera(eye, centre, yfov_degrees=40.0, znear=0.01, zfar=1000.0)
        return b
    return build


WORKLOADS = [
    ("city-1080p", city, "a city block: many textured draws, 20 textures"),
    ("billboards-blend-1080p", billboards, "240 alpha-blended billboards, ~25 layers a pixel"),
    ("closeup-4k", closeup_4k, "a textured model close up at 3840x2160, 2048² texture"),
    ("interior-1080p", interior, "a textured interior: 287 draws, 24 textures, 3 alpha-masked"),
    ("vertex-colors-1080p", vertex_colors, "a 100 k-triangle scan with vertex colours only"),
    ("cad-assembly-1080p", cad_assembly, "a CAD assembly in ~2 000 draws of ~128 triangles"),
    ("cad-thumbnail-256", cad_thumbnail, "a CAD model, 121 k triangles in 115 draws, 256x256"),
    ("scan-1080p", scan(1.8), "a 1.6 M-triangle scan filling a 1920x1080 frame"),
    ("scan-far-1080p", scan(0.12), "the same scan far away: sub-pixel triangles"),
]


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", help="folder to write the .glb files and workloads.json into")
    parser.add_argument("--shared", default=os.environ.get("KANTELE_SHARED", os.path.join(root, "..", "shared")),
                        help="the shared folder holding scenes/ and realworld/ (default: $KANTELE_SHARED or ../shared)")
    parser.add_argument("--only", nargs="*", help="build only these workloads")
    args = parser.parse_args()
    for needed in ("scenes", "realworld"):
        if not os.path.isdir(os.path.join(args.shared, needed)):
            sys.exit(f"generate: no {needed}/ in {args.shared} (pass --shared or set KANTELE_SHARED)")
    os.makedirs(args.out, exist_ok=True)
    index = []
    for name, build, about in WORKLOADS:
        if args.only and name not in args.only:
            continue
        builder = build(args.shared, args.out)
        builder.write(os.path.join(args.out, name + ".glb"))
        entry = {"name": name, "about": about, "resolution": list(builder.resolution),
                 "triangles": builder.triangles, "draws": builder.draws,
                 "textures": len(builder.json.get("textures", []))}
        index.append(entry)
        print(f"generate: {name}: {builder.triangles} triangles, {builder.draws} draws, "
              f"{entry['textures']} textures, {builder.resolution[0]}x{builder.resolution[1]}", file=sys.stderr)
    with open(os.path.join(args.out, "workloads.json"), "w") as f:
        json.dump(index, f, indent=1)


if __name__ == "__main__":
    main()
