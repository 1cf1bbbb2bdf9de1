"""The files the README's examples name (`scene.glb`, `walk.glb`, `part.obj`, ...), written into
a folder so that every example runs as written: a small glTF with two scenes, a material variant
`Blue`, a camera and an animation `Walk`, as `.glb` and `.gltf`, and an OBJ."""

import base64
import json
import struct
from pathlib import Path

# A unit cube's 8 corners and 12 triangles (counter-clockwise seen from outside).
_CORNERS = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
_FACES = [
    (0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4),
    (2, 6, 3), (3, 6, 7), (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5),
]


def _buffer() -> bytes:
    positions = b"".join(struct.pack("<3f", *c) for c in _CORNERS)
    indices = b"".join(struct.pack("<3H", *f) for f in _FACES)
    times = struct.pack("<2f", 0.0, 2.0)
    moves = struct.pack("<6f", 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    return positions + indices + times + moves


def gltf_document() -> dict:
    """The glTF JSON, without a buffer URI."""
    n_pos, n_idx = 8 * 12, 36 * 2
    views = [
        {"buffer": 0, "byteOffset": 0, "byteLength": n_pos},
        {"buffer": 0, "byteOffset": n_pos, "byteLength": n_idx},
        {"buffer": 0, "byteOffset": n_pos + n_idx, "byteLength": 8},
        {"buffer": 0, "byteOffset": n_pos + n_idx + 8, "byteLength": 24},
    ]
    accessors = [
        {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3",
         "min": [-0.5] * 3, "max": [0.5] * 3},
        {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5126, "count": 2, "type": "SCALAR",
         "min": [0.0], "max": [2.0]},
        {"bufferView": 3, "componentType": 5126, "count": 2, "type": "VEC3"},
    ]
    variant = {"mappings": [{"material": 1, "variants": [0]}]}
    return {
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_variants"],
        "extensions": {"KHR_materials_variants": {"variants": [{"name": "Blue"}]}},
        "scene": 0,
        "scenes": [{"name": "one", "nodes": [0, 2]}, {"name": "two", "nodes": [1, 2]}],
        "nodes": [
            {"name": "cube", "mesh": 0},
            {"name": "moved", "mesh": 0, "translation": [1.0, 0.0, 0.0]},
            {"name": "camera", "camera": 0, "translation": [0.0, 0.5, 4.0]},
        ],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.7, "znear": 0.1, "aspectRatio": 1.5}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1,
                                    "material": 0,
                                    "extensions": {"KHR_materials_variants": variant}}]}],
        "materials": [
            {"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.3, 0.2, 1.0]}},
            {"pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.2, 0.9, 1.0]}},
        ],
        "animations": [{"name": "Walk",
                        "samplers": [{"input": 2, "output": 3}],
                        "channels": [{"sampler": 0,
                                      "target": {"node": 0, "path": "translation"}}]}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(_buffer())}],
    }


def glb_bytes() -> bytes:
    """The document as a binary glTF."""
    text = json.dumps(gltf_document()).encode()
    text += b" " * (-len(text) % 4)
    data = _buffer()
    data += b"\0" * (-len(data) % 4)
    chunks = (struct.pack("<I4s", len(text), b"JSON") + text
              + struct.pack("<I4s", len(data), b"BIN\0") + data)
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


def gltf_text() -> str:
    """The document as a `.gltf` with its buffer embedded."""
    doc = gltf_document()
    doc["buffers"][0]["uri"] = ("data:application/octet-stream;base64,"
                                + base64.b64encode(_buffer()).decode())
    return json.dumps(doc)


OBJ = "".join(f"v {x} {y} {z}\n" for x, y, z in _CORNERS) + "".join(
    f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in _FACES
)

GLB_NAMES = ["scene.glb", "model.glb", "walk.glb", "a.glb", "b.glb", "scans/scan.glb",
             "more/more.glb", "scenes/model.glb"]


def write(folder: Path) -> None:
    """Writes every file the README's examples read into `folder`."""
    for name in GLB_NAMES:
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(glb_bytes())
    (folder / "scenes.gltf").write_text(gltf_text())
    (folder / "part.obj").write_text(OBJ)
