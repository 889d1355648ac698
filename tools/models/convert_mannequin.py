#!/usr/bin/env python3
"""Converts the "wooden" mannequin of the PyPI wheel mannequin-x 0.3.0 (Apache-2.0) into one
glTF 2.0 binary, third_party_models/mannequin/wooden_mannequin.glb, and writes its section of
third_party_models/MODELS.md (the section "## mannequin_wooden", after the project's own
sections; write_models_md.py keeps everything from "## gesture_lstm (ours)" on unchanged).

    tools/setup.sh                                   # installs mannequin-x into the tools venv
    /opt/gesture_formation/venv/bin/python tools/models/convert_mannequin.py

What the .glb holds (docs/rendering.md "The asset"):
- one skinned mesh: the wheel's source vertices (24,256) and triangles (48,396), in metres,
  glTF axes (+y up, +z the figure's front, +x its left), feet on y = 0 (the wheel's vertices
  shifted up by their lowest y); smooth vertex normals (area-weighted);
- JOINTS_0 / WEIGHTS_0: the 4 strongest of the wheel's 8 skin influences per vertex,
  renormalised, and the wheel's rigid parts bound to their one joint — exactly what the
  wheel's own runtime (Mannequin._bind_skin) does;
- the skeleton: 54 nodes named with the SMPL-X joint names of the wheel's runtime
  (Pelvis, L_Hip, ..., Spine1..3, L_Collar, ...; plus zero-length L_Hand/R_Hand and the
  fingers), bind pose = the joint positions the skin was bound to (`skin_source_joint_positions`),
  no rest rotations; inverseBindMatrices are pure translations.

Reads only the wheel's data file (assets/wooden.npz) with numpy; the wheel's runtime (which
needs numpy >= 2, jaxtyping, nanomanifold) is not imported, so the wheel is installed with
--no-deps. Deterministic: the same wheel gives a byte-identical file.
"""
import argparse
import hashlib
import importlib.metadata
import importlib.util
import json
import os
import struct
import sys

import numpy as np

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
OUT_REL = "third_party_models/mannequin/wooden_mannequin.glb"
SECTION = "## mannequin_wooden"
PACKAGE, VERSION = "mannequin-x", "0.3.0"
# the wheel runtime's renaming to SMPL-X joint names (mannequin/_model.py SMPLX_JOINT_NAMES)
SMPLX_NAMES = {"Torso": "Spine1", "Spine": "Spine2", "Chest": "Spine3", "L_Toe": "L_Foot", "R_Toe": "R_Foot",
               "L_Thorax": "L_Collar", "R_Thorax": "R_Collar"}


def wheel_asset():
    spec = importlib.util.find_spec("mannequin")  # finds the package without running its __init__
    if spec is None or not spec.submodule_search_locations:
        sys.exit(f"convert_mannequin: the PyPI package {PACKAGE}=={VERSION} is not installed in {sys.prefix}; "
                 f"run tools/setup.sh (or: {sys.prefix}/bin/pip install --no-deps {PACKAGE}=={VERSION})")
    have = importlib.metadata.version(PACKAGE)
    if have != VERSION:
        sys.exit(f"convert_mannequin: {PACKAGE} {have} installed, {VERSION} required (tools/setup.sh)")
    return os.path.join(list(spec.submodule_search_locations)[0], "assets", "wooden.npz")


def skin_bindings(d):
    """Top-4 influences renormalised, rigid parts on their one joint (Mannequin._bind_skin)."""
    idx = d["skin_joint_indices"].astype(np.int64)
    w = d["skin_weights"].astype(np.float64)
    strongest = np.argsort(w, axis=1, kind="stable")[:, -4:]
    idx = np.take_along_axis(idx, strongest, axis=1)
    w = np.take_along_axis(w, strongest, axis=1)
    w /= w.sum(axis=1, keepdims=True)
    rigid = d["skin_rigid_joint_indices"].astype(np.int64)
    r = rigid >= 0
    idx[r] = rigid[r, None]
    w[r] = 0.0
    w[r, 0] = 1.0
    # strongest first (readers that keep fewer influences keep the right ones)
    order = np.argsort(-w, axis=1, kind="stable")
    idx = np.take_along_axis(idx, order, axis=1)
    w = np.take_along_axis(w, order, axis=1)
    idx[w == 0.0] = 0
    return idx.astype(np.uint16), w.astype(np.float32)


def vertex_normals(v, f):
    n = np.zeros_like(v, dtype=np.float64)
    fn = np.cross(v[f[:, 1]] - v[f[:, 0]], v[f[:, 2]] - v[f[:, 0]])  # area-weighted
    for k in range(3):
        np.add.at(n, f[:, k], fn)
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-12)
    return n.astype(np.float32)


class Bin:
    def __init__(self):
        self.data = bytearray()
        self.views, self.accessors = [], []

    def add(self, arr, comp, typ, target=None, minmax=False):
        while len(self.data) % 4:
            self.data.append(0)
        raw = np.ascontiguousarray(arr).tobytes()
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(raw)}
        if target:
            view["target"] = target
        self.views.append(view)
        self.data += raw
        count = arr.shape[0]
        acc = {"bufferView": len(self.views) - 1, "componentType": comp, "count": count, "type": typ}
        if minmax:
            acc["min"] = [float(x) for x in arr.min(axis=0)]
            acc["max"] = [float(x) for x in arr.max(axis=0)]
        self.accessors.append(acc)
        return len(self.accessors) - 1


def build_glb(d):
    verts = d["vertices"].astype(np.float32).copy()
    floor = float(verts[:, 1].min())
    verts[:, 1] -= floor
    faces = d["faces"].astype(np.uint32)
    joints = d["skin_source_joint_positions"].astype(np.float32).copy()
    joints[:, 1] -= floor
    parents = d["parents"].astype(np.int64).tolist()
    names = [SMPLX_NAMES.get(n, n) for n in d["joint_names"].tolist()]
    idx, w = skin_bindings(d)
    normals = vertex_normals(verts.astype(np.float64), faces.astype(np.int64))

    b = Bin()
    a_pos = b.add(verts, 5126, "VEC3", 34962, minmax=True)
    a_nrm = b.add(normals, 5126, "VEC3", 34962)
    a_jnt = b.add(idx, 5123, "VEC4", 34962)
    a_wgt = b.add(w, 5126, "VEC4", 34962)
    a_idx = b.add(faces.reshape(-1, 1), 5125, "SCALAR", 34963)
    ibm = np.zeros((len(names), 16), np.float32)  # column-major 4x4: translation by -bind position
    ibm[:, 0] = ibm[:, 5] = ibm[:, 10] = ibm[:, 15] = 1.0
    ibm[:, 12:15] = -joints
    a_ibm = b.add(ibm, 5126, "MAT4")

    # nodes: 0 = the mesh, 1.. = joints (node 1 + j is joint j)
    nodes = [{"name": "wooden_mannequin", "mesh": 0, "skin": 0}]
    for j, name in enumerate(names):
        p = parents[j]
        t = joints[j] - (joints[p] if p >= 0 else 0.0)
        node = {"name": name, "translation": [float(x) for x in t]}
        kids = [1 + c for c in range(len(names)) if parents[c] == j]
        if kids:
            node["children"] = kids
        nodes.append(node)
    root = 1 + parents.index(-1)
    gltf = {
        "asset": {"version": "2.0", "generator": "gesture_formation tools/models/convert_mannequin.py",
                  "copyright": f"{PACKAGE} {VERSION} (Apache-2.0), wooden mannequin"},
        "scene": 0,
        "scenes": [{"nodes": [0, root]}],
        "nodes": nodes,
        "meshes": [{"name": "wooden_mannequin", "primitives": [{
            "attributes": {"POSITION": a_pos, "NORMAL": a_nrm, "JOINTS_0": a_jnt, "WEIGHTS_0": a_wgt},
            "indices": a_idx, "mode": 4}]}],
        "skins": [{"name": "smplx", "inverseBindMatrices": a_ibm, "skeleton": root,
                   "joints": [1 + j for j in range(len(names))]}],
        "buffers": [{"byteLength": len(b.data)}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    }
    js = json.dumps(gltf, separators=(",", ":"), sort_keys=True).encode()
    js += b" " * (-len(js) % 4)
    bn = bytes(b.data) + b"\0" * (-len(b.data) % 4)
    total = 12 + 8 + len(js) + 8 + len(bn)
    out = struct.pack("<4sII", b"glTF", 2, total)
    out += struct.pack("<I4s", len(js), b"JSON") + js
    out += struct.pack("<I4s", len(bn), b"BIN\0") + bn
    return out, {"vertices": len(verts), "triangles": len(faces), "joints": len(names),
                 "height_m": float(verts[:, 1].max())}


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    return h.hexdigest()


def write_section(md_path, text):
    old = open(md_path, encoding="utf-8").read() if os.path.exists(md_path) else ""
    if SECTION in old:
        start = old.index(SECTION)
        nxt = old.find("\n## ", start + len(SECTION))
        old = old[:start].rstrip("\n") + ("\n\n" + old[nxt + 1:] if nxt >= 0 else "")
    new = old.rstrip("\n") + "\n\n" + text
    with open(md_path, "w", encoding="utf-8") as f:
        f.write(new)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", default=os.path.join(ROOT, OUT_REL))
    ap.add_argument("--models-md", default=os.path.join(ROOT, "third_party_models", "MODELS.md"))
    a = ap.parse_args()
    asset = wheel_asset()
    with np.load(asset, allow_pickle=False) as d:
        data = {k: d[k] for k in d.files}
    glb, info = build_glb(data)
    os.makedirs(os.path.dirname(a.out), exist_ok=True)
    with open(a.out, "wb") as f:
        f.write(glb)
    dist = importlib.metadata.distribution(PACKAGE)
    licence = dist.metadata.get("License-Expression") or dist.metadata.get("License") or "?"
    text = "\n".join([
        SECTION, "",
        f"- file: `{OUT_REL}` — {len(glb) / 1e6:.1f} MB (glTF 2.0 binary: one skinned mesh, {info['vertices']} vertices, "
        f"{info['triangles']} triangles, {info['joints']}-joint SMPL-X skeleton, 4 skin weights per vertex; "
        f"{info['height_m']:.3f} m tall, +y up, +z front, feet at y = 0)",
        f"- sha256: `{sha256(a.out)}`",
        f"- source package: PyPI `{PACKAGE}=={VERSION}` (wheel `mannequin_x-{VERSION}-py3-none-any.whl`, installed "
        f"into the tools venv by `tools/setup.sh` with `--no-deps`)",
        "- path inside the package: `mannequin/assets/wooden.npz` (arrays `vertices`, `faces`, `joint_names`, `parents`, "
        "`skin_source_joint_positions`, `skin_joint_indices`, `skin_weights`, `skin_rigid_joint_indices`; its "
        f"`source_sha256` {str(data['source_sha256'])[:12]}…)",
        f"- licence: {licence} (wheel METADATA `License-Expression`)",
        "- conversion: `/opt/gesture_formation/venv/bin/python tools/models/convert_mannequin.py` (also run by "
        "`tools/models/convert_all.sh`); regenerating gives a byte-identical file",
        "- use: `render::WorkerMesh` (docs/rendering.md) loads it with Assimp, dresses it by per-joint vertex colours and "
        "poses it by linear blend skinning from the worker model's joints.",
        "",
    ])
    write_section(a.models_md, text)
    print(f"convert_mannequin: wrote {a.out} ({len(glb)} bytes, sha256 {sha256(a.out)}) and its section of {a.models_md}")


if __name__ == "__main__":
    main()
