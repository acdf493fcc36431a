#!/usr/bin/env python3
"""Writes the plain glTF inputs of docs/robustness.md's memory table (standard library only).

Usage: scripts/memory_inputs.py DIR

Every file is a .gltf with its .bin beside it (and a .png where it has a texture):
  tri            one triangle: the base that the table subtracts
  grid_N         one indexed grid of 2 N^2 triangles, positions and uint32 indices only
  grid_attr_N    the same with NORMAL and TEXCOORD_0
  meshes_M_of_N  M distinct meshes (one node each), each a grid of 2 N^2 triangles
  nodes_K_of_N   one grid of 2 N^2 triangles referenced from K nodes
  gpu_K_of_N     one grid of 2 N^2 triangles on one node with K EXT_mesh_gpu_instancing instances
  tex_S          a quad with an S x S RGBA8 PNG base colour texture
  quads_1eD      one quad instanced 10^D times by a tree of nodes, 10 children a level
  prims_P_x_K    one mesh of P quad primitives, referenced from K nodes
  quad_nodes_N   N root nodes of one quad mesh

The compressed inputs (Draco, meshopt) come from make_compressed_gltf (fuzz/); scripts/measure_memory.sh
runs both and prints the table.
"""
import json
import os
import struct
import sys
import zlib
from array import array


class Gltf:
    def __init__(self):
        self.doc = {"asset": {"version": "2.0"}, "buffers": [], "bufferViews": [], "accessors": [],
                    "meshes": [], "nodes": [], "scenes": [{"nodes": []}], "scene": 0}
        self.bin = bytearray()

    def view(self, data):
        while len(self.bin) % 4:
            self.bin.append(0)
        self.doc["bufferViews"].append({"buffer": 0, "byteOffset": len(self.bin), "byteLength": len(data)})
        self.bin += data
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, data, component, count, kind, lo=None, hi=None):
        a = {"bufferView": self.view(data), "componentType": component, "count": count, "type": kind}
        if lo is not None:
            a["min"], a["max"] = lo, hi
        self.doc["accessors"].append(a)
        return len(self.doc["accessors"]) - 1

    def grid_mesh(self, n, attributes=False, material=None):
        pos = array("f")
        nrm = array("f")
        uv = array("f")
        for j in range(n + 1):
            for i in range(n + 1):
                pos.extend((i / n, j / n, 0.0))
                if attributes:
                    nrm.extend((0.0, 0.0, 1.0))
                    uv.extend((i / n, j / n))
        idx = array("I")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i
                idx.extend((a, a + 1, a + n + 2, a, a + n + 2, a + n + 1))
        count = (n + 1) ** 2
        attrs = {"POSITION": self.accessor(pos.tobytes(), 5126, count, "VEC3", [0, 0, 0], [1, 1, 0])}
        if attributes:
            attrs["NORMAL"] = self.accessor(nrm.tobytes(), 5126, count, "VEC3")
            attrs["TEXCOORD_0"] = self.accessor(uv.tobytes(), 5126, count, "VEC2")
        prim = {"attributes": attrs, "indices": self.accessor(idx.tobytes(), 5125, len(idx), "SCALAR")}
        if material is not None:
            prim["material"] = material
        self.doc["meshes"].append({"primitives": [prim]})
        return len(self.doc["meshes"]) - 1

    def quad_mesh(self, count=1):
        """One mesh of `count` unit quads (each its own primitive and accessors)."""
        prims = []
        for _ in range(count):
            pos = array("f", (0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0))
            idx = array("I", (0, 1, 2, 0, 2, 3))
            prims.append({"attributes": {"POSITION": self.accessor(pos.tobytes(), 5126, 4, "VEC3", [0, 0, 0], [1, 1, 0])},
                          "indices": self.accessor(idx.tobytes(), 5125, 6, "SCALAR")})
        self.doc["meshes"].append({"primitives": prims})
        return len(self.doc["meshes"]) - 1

    def node(self, **fields):
        self.doc["nodes"].append(fields)
        return len(self.doc["nodes"]) - 1

    def root(self, node):
        self.doc["scenes"][0]["nodes"].append(node)

    def write(self, path):
        name = os.path.basename(path)[:-5] + ".bin"
        self.doc["buffers"] = [{"uri": name, "byteLength": len(self.bin)}]
        with open(os.path.join(os.path.dirname(path), name), "wb") as f:
            f.write(self.bin)
        with open(path, "w") as f:
            json.dump({k: v for k, v in self.doc.items() if v != []}, f)


def png(width, height):
    """An RGBA8 PNG of a smooth gradient (compresses well: a small file that decodes large)."""
    rows = bytearray()
    for y in range(height):
        rows.append(0)
        g = y * 255 // max(height - 1, 1)
        rows += bytes((x * 255 // max(width - 1, 1), g, 128, 255)[c] for x in range(width) for c in range(4))
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 6, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(bytes(rows), 9)) + chunk(b"IEND", b""))


def main(out):
    os.makedirs(out, exist_ok=True)
    g = Gltf()
    pos = array("f", (0, 0, 0, 1, 0, 0, 0, 1, 0))
    a = g.accessor(pos.tobytes(), 5126, 3, "VEC3", [0, 0, 0], [1, 1, 0])
    g.doc["meshes"].append({"primitives": [{"attributes": {"POSITION": a}}]})
    g.root(g.node(mesh=0))
    g.write(f"{out}/tri.gltf")
    for n in (50, 100, 150, 200, 230):
        g = Gltf()
        g.root(g.node(mesh=g.grid_mesh(n)))
        g.write(f"{out}/grid_{n}.gltf")
    g = Gltf()
    g.root(g.node(mesh=g.grid_mesh(150, attributes=True)))
    g.write(f"{out}/grid_attr_150.gltf")
    for m, n in ((1000, 5), (100, 20)):
        g = Gltf()
        for i in range(m):
            g.root(g.node(mesh=g.grid_mesh(n), translation=[1.1 * (i % 40), 1.1 * (i // 40), 0]))
        g.write(f"{out}/meshes_{m}_of_{n}.gltf")
    for k, n in ((3, 100), (10, 100), (40, 100), (100, 100)):
        g = Gltf()
        mesh = g.grid_mesh(n)
        for i in range(k):
            g.root(g.node(mesh=mesh, translation=[1.1 * (i % 8), 1.1 * (i // 8), 0]))
        g.write(f"{out}/nodes_{k}_of_{n}.gltf")
    for k, n in ((200, 50), (1000, 20)):
        g = Gltf()
        mesh = g.grid_mesh(n)
        t = array("f")
        for i in range(k):
            t.extend((1.1 * (i % 32), 1.1 * (i // 32), 0.0))
        tr = g.accessor(t.tobytes(), 5126, k, "VEC3")
        g.root(g.node(mesh=mesh, extensions={"EXT_mesh_gpu_instancing": {"attributes": {"TRANSLATION": tr}}}))
        g.doc["extensionsUsed"] = ["EXT_mesh_gpu_instancing"]
        g.write(f"{out}/gpu_{k}_of_{n}.gltf")
    for d in (4, 5):
        g = Gltf()
        child = g.node(mesh=g.quad_mesh())
        for level in range(d):
            child = g.node(children=[g.node(children=[child], translation=[1.1 * i * 10 ** level, 0, 0])
                                     for i in range(10)])
        g.root(child)
        g.write(f"{out}/quads_1e{d}.gltf")
    g = Gltf()
    mesh = g.quad_mesh(2000)
    for i in range(100):
        g.root(g.node(mesh=mesh, translation=[0, 0, 0.01 * i]))
    g.write(f"{out}/prims_2000_x100.gltf")
    g = Gltf()
    mesh = g.quad_mesh()
    for i in range(20000):
        g.root(g.node(mesh=mesh, translation=[1.1 * (i % 150), 1.1 * (i // 150), 0]))
    g.write(f"{out}/quad_nodes_20000.gltf")
    for s in (2048, 4096):
        g = Gltf()
        with open(f"{out}/tex_{s}.png", "wb") as f:
            f.write(png(s, s))
        g.doc["images"] = [{"uri": f"tex_{s}.png"}]
        g.doc["textures"] = [{"source": 0}]
        g.doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        g.root(g.node(mesh=g.grid_mesh(1, attributes=True, material=0)))
        g.write(f"{out}/tex_{s}.gltf")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
