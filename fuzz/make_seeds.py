#!/usr/bin/env python3
"""Writes the hand-made seed inputs of fuzz/corpus/ (standard library only):
  gltf_scene/   small glTF and GLB scenes covering the loader's features and edge cases, and the
                built-in cornell scene packed into one GLB;
  exr_reader/   scanline EXRs, uncompressed, RLE, ZIPS and ZIP, float/half/uint, odd data windows;
  hdr_reader/   Radiance HDR, flat and run-length encoded scanlines;
  png_reader/   PNG in every colour type and bit depth stb reads, plus a few other formats.
The gltf_scene seeds named compressed_* (Draco, meshopt, WebP, KTX2 and GPU instancing, valid and
malformed) need the libraries' encoders, so a C++ program writes them:
  cmake --build build --target make_compressed_gltf && build/fuzz/make_compressed_gltf seeds fuzz/corpus/gltf_scene
The state_reader seeds: the named ones are written by fuzz/make_state_seeds.sh with `pxf render`
and `pxf merge` (rerun it after a state format version bump); the ones named by their SHA-1 are
inputs the campaigns kept, as libFuzzer names them. Rendered EXR/PNG outputs come from `pxf render`.
Usage: fuzz/make_seeds.py [corpus folder, default fuzz/corpus]"""
import base64, json, math, os, struct, sys, zlib

ROOT = os.path.dirname(os.path.abspath(__file__))
OUT = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "corpus")


def put(harness, name, data):
    folder = os.path.join(OUT, harness)
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


# --------------------------------------------------------------------------------------------- PNG
def png(width, height, color_type, bit_depth, rows, palette=None, trns=None, interlace=0):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + r for r in rows)
    out = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, bit_depth, color_type, 0, 0, interlace))
    if palette:
        out += chunk(b"PLTE", palette)
    if trns:
        out += chunk(b"tRNS", trns)
    return out + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b"")


def png_seeds():
    w = h = 3
    samples = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}
    for ct, depths in {0: (1, 2, 4, 8, 16), 2: (8, 16), 3: (1, 2, 4, 8), 4: (8, 16), 6: (8, 16)}.items():
        for d in depths:
            bits_per_row = w * samples[ct] * d
            row = bytes((37 * i + 11) & 0xFF for i in range((bits_per_row + 7) // 8))
            pal = bytes(range(48)) if ct == 3 else None
            put("png_reader", f"ct{ct}_d{d}.png", png(w, h, ct, d, [row] * h, palette=pal))
    put("png_reader", "trns_rgb.png", png(2, 2, 2, 8, [b"\x01\x02\x03\x04\x05\x06"] * 2, trns=b"\x00\x01\x00\x02\x00\x03"))
    put("png_reader", "palette_trns.png", png(2, 2, 3, 8, [b"\x00\x01"] * 2, palette=b"\xff\x00\x00\x00\xff\x00", trns=b"\x80"))
    # Adam7 interlacing of a 1x1 image: a single pass with one pixel.
    put("png_reader", "interlaced_1x1.png", png(1, 1, 2, 8, [b"\x10\x20\x30"], interlace=1))
    put("png_reader", "truncated.png", png(4, 4, 6, 8, [bytes(16)] * 4)[:40])
    put("png_reader", "huge_header.png", png(16384, 16384, 6, 8, [b""])[:60])
    # Other formats stb sniffs: BMP, TGA, PNM, GIF header.
    bmp_pixels = b"\x00\x00\xff\x00\xff\x00\x00\x00"  # 2x1, 24-bit, rows padded to 4 bytes
    put("png_reader", "tiny.bmp", b"BM" + struct.pack("<IHHI", 54 + len(bmp_pixels), 0, 0, 54) +
        struct.pack("<IiiHHIIiiII", 40, 2, 1, 1, 24, 0, len(bmp_pixels), 2835, 2835, 0, 0) + bmp_pixels)
    put("png_reader", "tiny.tga", struct.pack("<BBBHHBHHHHBB", 0, 0, 2, 0, 0, 0, 0, 0, 2, 1, 24, 0) + b"\x01\x02\x03\x04\x05\x06")
    put("png_reader", "tiny.ppm", b"P6\n2 1\n255\n\x01\x02\x03\x04\x05\x06")
    put("png_reader", "tiny.pgm", b"P5\n2 2\n65535\n" + bytes(8))


# --------------------------------------------------------------------------------------------- HDR
def hdr_seeds():
    def header(w, h, extra=""):
        return f"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\nEXPOSURE=1.0{extra}\n\n-Y {h} +X {w}\n".encode()
    flat = bytes([128, 64, 32, 129, 0, 0, 0, 0, 255, 255, 255, 255, 1, 1, 1, 1])  # incl. an Inf-like exponent
    put("hdr_reader", "flat_2x2.hdr", header(2, 2) + flat)
    # New-style RLE scanline of width 8: 2 2 hi lo, then per channel a run and a literal.
    w = 8
    line = bytes([2, 2, w >> 8, w & 0xFF])
    for c in range(4):
        line += bytes([128 + 4, 100 + c]) + bytes([4, 1, 2, 3, 4])
    put("hdr_reader", "rle_8x2.hdr", header(w, 2) + line * 2)
    put("hdr_reader", "old_rle.hdr", header(4, 1) + bytes([10, 20, 30, 128, 1, 1, 1, 3]))
    put("hdr_reader", "rgbe_magic.hdr", b"#?RGBE\n\n-Y 1 +X 1\n" + bytes([1, 2, 3, 128]))
    put("hdr_reader", "truncated.hdr", header(64, 64) + bytes([2, 2, 0, 64, 130, 5]))
    put("hdr_reader", "huge.hdr", header(1 << 20, 1 << 20))


# --------------------------------------------------------------------------------------------- EXR
def exr(channels, width, height, compression, pixel_fn, window=None, line_order=0, extra=b""):
    """Scanline EXR. channels: list of (name, type) with type 0 uint, 1 half, 2 float."""
    xmin, ymin = window or (0, 0)
    xmax, ymax = xmin + width - 1, ymin + height - 1

    def attr(name, kind, body):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(body)) + body

    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", t, 0, 1, 1) for n, t in channels) + b"\0"
    head = struct.pack("<ii", 20000630, 2)
    head += attr("channels", "chlist", chlist)
    head += attr("compression", "compression", bytes([compression]))
    head += attr("dataWindow", "box2i", struct.pack("<iiii", xmin, ymin, xmax, ymax))
    head += attr("displayWindow", "box2i", struct.pack("<iiii", xmin, ymin, xmax, ymax))
    head += attr("lineOrder", "lineOrder", bytes([line_order]))
    head += attr("pixelAspectRatio", "float", struct.pack("<f", 1.0))
    head += attr("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0))
    head += attr("screenWindowWidth", "float", struct.pack("<f", 1.0))
    head += extra + b"\0"
    lines_per_block = {0: 1, 1: 1, 2: 1, 3: 16}[compression]
    sorted_channels = sorted(channels)

    def line_bytes(y):
        out = b""
        for name, t in sorted_channels:
            for x in range(width):
                v = pixel_fn(x, y, name)
                out += struct.pack("<I", int(abs(v)) & 0xFFFFFFFF) if t == 0 else struct.pack("<e", v) if t == 1 else struct.pack("<f", v)
        return out

    def zip_pack(raw):
        half = (len(raw) + 1) // 2
        shuffled = bytearray(len(raw))
        shuffled[:half] = raw[0::2]
        shuffled[half:] = raw[1::2]
        pred = bytearray(shuffled)
        for i in range(len(pred) - 1, 0, -1):
            pred[i] = (shuffled[i] - shuffled[i - 1] + 128 + 256) & 0xFF
        return bytes(pred)

    def rle(data):
        out, i = bytearray(), 0
        while i < len(data):
            run = 1
            while i + run < len(data) and data[i + run] == data[i] and run < 128:
                run += 1
            if run >= 3:
                out += struct.pack("<b", run - 1) + data[i:i + 1]
                i += run
            else:
                j = i
                while j < len(data) and j - i < 127 and not (j + 2 < len(data) and data[j] == data[j + 1] == data[j + 2]):
                    j += 1
                out += struct.pack("<b", -(j - i)) + data[i:j]
                i = j
        return bytes(out)

    blocks = []
    for y0 in range(ymin, ymax + 1, lines_per_block):
        raw = b"".join(line_bytes(y) for y in range(y0, min(y0 + lines_per_block, ymax + 1)))
        if compression == 1:
            packed = rle(zip_pack(raw))
        elif compression in (2, 3):
            packed = zlib.compress(zip_pack(raw))
        else:
            packed = raw
        if len(packed) >= len(raw):
            packed = raw  # EXR stores a block uncompressed when compression does not pay
        blocks.append(struct.pack("<ii", y0, len(packed)) + packed)
    offset = len(head) + 8 * len(blocks)
    table = b""
    for b in blocks:
        table += struct.pack("<Q", offset)
        offset += len(b)
    return head + table + b"".join(blocks)


def exr_seeds():
    rgb = [("R", 2), ("G", 2), ("B", 2)]
    ramp = lambda x, y, c: 0.25 * x + 0.5 * y + {"R": 0.0, "G": 1.0, "B": 2.0}.get(c, 3.0)
    for comp, name in [(0, "none"), (1, "rle"), (2, "zips"), (3, "zip")]:
        put("exr_reader", f"rgb_float_{name}.exr", exr(rgb, 4, 3, comp, ramp))
    put("exr_reader", "rgba_half_zip.exr", exr([("R", 1), ("G", 1), ("B", 1), ("A", 1)], 5, 17, 3, ramp))
    put("exr_reader", "layers.exr", exr([("final.R", 2), ("final.G", 2), ("final.B", 2), ("var_u.Y", 2), ("samples.Y", 0)], 3, 2, 0, ramp))
    put("exr_reader", "window_offset.exr", exr([("Y", 2)], 2, 2, 0, ramp, window=(-5, 1000)))
    special = [float("inf"), float("-inf"), float("nan"), 3.0e38, 1e-45, -0.0]
    put("exr_reader", "nonfinite.exr", exr(rgb, 2, 1, 0, lambda x, y, c: special[(x * 3 + "RGB".index(c)) % 6]))
    put("exr_reader", "decreasing_y.exr", exr(rgb, 2, 2, 2, ramp, line_order=1))
    put("exr_reader", "truncated.exr", exr(rgb, 8, 8, 3, ramp)[:-20])
    # Header attributes whose declared length OpenEXR would allocate or misread: an unknown type of
    # 2 GiB, a box2i of 256 bytes, a preview of 65535^2 pixels.
    put("exr_reader", "attribute_past_end.exr", exr(rgb, 2, 2, 0, ramp, extra=b"junk\0opaque_t\0" + struct.pack("<i", 2**31 - 1)))
    put("exr_reader", "box2i_wrong_length.exr", exr(rgb, 2, 2, 0, ramp, extra=b"box\0box2i\0" + struct.pack("<i", 256) + bytes(256)))
    put("exr_reader", "huge_preview.exr", exr(rgb, 2, 2, 0, ramp, extra=b"preview\0preview\0" + struct.pack("<iII", 8, 65535, 65535)))
    put("exr_reader", "tiles_huge.exr", exr(rgb, 2, 2, 0, ramp, extra=b"tiles\0tiledesc\0" + struct.pack("<iIIB", 9, 1 << 20, 1 << 20, 0)))
    huge = exr([("Y", 2)], 1, 1, 0, ramp)
    key = b"dataWindow\0box2i\0" + struct.pack("<i", 16)
    at = huge.index(key) + len(key)
    huge = huge[:at] + struct.pack("<iiii", -2**31, -2**31, 2**31 - 1, 2**31 - 1) + huge[at + 16:]
    put("exr_reader", "huge_window.exr", huge)


# --------------------------------------------------------------------------------------------- glTF
def data_uri(raw):
    return "data:application/octet-stream;base64," + base64.b64encode(raw).decode()


def gltf(doc, buffers):
    doc.setdefault("asset", {"version": "2.0"})
    doc["buffers"] = [{"byteLength": len(b), "uri": data_uri(b)} for b in buffers]
    return json.dumps(doc, separators=(",", ":"))


def glb(doc, bin_chunk):
    doc.setdefault("asset", {"version": "2.0"})
    doc["buffers"] = [{"byteLength": len(bin_chunk)}]
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    bin_chunk += b"\0" * (-len(bin_chunk) % 4)
    body = struct.pack("<I4s", len(js), b"JSON") + js + struct.pack("<I4s", len(bin_chunk), b"BIN\0") + bin_chunk
    return struct.pack("<4sII", b"glTF", 2, 12 + len(body)) + body


def quad_buffer():
    pos = [(-1, 0, -1), (1, 0, -1), (1, 0, 1), (-1, 0, 1)]
    nrm = [(0, 1, 0)] * 4
    uv = [(0, 0), (1, 0), (1, 1), (0, 1)]
    b = b"".join(struct.pack("<3f", *p) for p in pos) + b"".join(struct.pack("<3f", *n) for n in nrm)
    b += b"".join(struct.pack("<2f", *t) for t in uv) + struct.pack("<6H", 0, 1, 2, 0, 2, 3)
    return b


def quad_views(buffer=0):
    views = [{"buffer": buffer, "byteOffset": 0, "byteLength": 48}, {"buffer": buffer, "byteOffset": 48, "byteLength": 48},
             {"buffer": buffer, "byteOffset": 96, "byteLength": 32}, {"buffer": buffer, "byteOffset": 128, "byteLength": 12}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, 0, -1], "max": [1, 0, 1]},
                 {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                 {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                 {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
    return views, accessors


def gltf_seeds():
    tiny_png = png(2, 2, 2, 8, [b"\xff\x00\x00\x00\xff\x00", b"\x00\x00\xff\xff\xff\xff"])
    views, accessors = quad_views()
    prim = {"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}
    camera = {"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01, "aspectRatio": 1.0}}
    base = {
        "scene": 0, "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"mesh": 0}, {"camera": 0, "translation": [0, 1, 3]},
                  {"mesh": 0, "translation": [0, 2, 0], "rotation": [1, 0, 0, 0], "scale": [0.2, 0.2, 0.2]}],
        "meshes": [{"primitives": [prim]}], "cameras": [camera], "bufferViews": views, "accessors": accessors,
        "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.7, 0.6, 1], "metallicFactor": 0.1,
                                                "roughnessFactor": 0.5}, "emissiveFactor": [0, 0, 0]}],
    }
    put("gltf_scene", "quad.gltf", gltf(json.loads(json.dumps(base)), [quad_buffer()]))
    put("gltf_scene", "quad.glb", glb(json.loads(json.dumps(base)), quad_buffer()))

    lit = json.loads(json.dumps(base))
    lit["materials"].append({"emissiveFactor": [1, 1, 1],
                             "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 50}}})
    lit["meshes"].append({"primitives": [dict(prim, material=1)]})
    lit["nodes"][2]["mesh"] = 1
    lit["extensionsUsed"] = ["KHR_lights_punctual", "KHR_materials_emissive_strength"]
    lit["extensions"] = {"KHR_lights_punctual": {"lights": [
        {"type": "point", "color": [1, 1, 1], "intensity": 10},
        {"type": "spot", "intensity": 5, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.6}},
        {"type": "directional", "intensity": 2}]}}
    lit["nodes"] += [{"extensions": {"KHR_lights_punctual": {"light": i}}, "translation": [0, 3, 0]} for i in range(3)]
    lit["scenes"][0]["nodes"] += [3, 4, 5]
    put("gltf_scene", "lights.gltf", gltf(lit, [quad_buffer()]))

    tex = json.loads(json.dumps(base))
    buf = quad_buffer()
    tex["bufferViews"].append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(tiny_png)})
    tex["images"] = [{"bufferView": 4, "mimeType": "image/png"}, {"uri": "data:image/png;base64," + base64.b64encode(tiny_png).decode()}]
    tex["samplers"] = [{"wrapS": 33648, "wrapT": 33071, "magFilter": 9728}]
    tex["textures"] = [{"source": 0, "sampler": 0}, {"source": 1}]
    tex["extensionsUsed"] = ["KHR_texture_transform", "KHR_materials_transmission", "KHR_materials_ior",
                             "KHR_materials_specular", "KHR_materials_volume"]
    m = tex["materials"][0]
    m["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0, "extensions": {"KHR_texture_transform": {
        "offset": [0.5, 0.5], "rotation": 0.3, "scale": [2, 2], "texCoord": 0}}}
    m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {"index": 1}
    m["normalTexture"] = {"index": 1, "scale": 0.5}
    m["occlusionTexture"] = {"index": 0}
    m["emissiveTexture"] = {"index": 1}
    m["alphaMode"] = "MASK"
    m["alphaCutoff"] = 0.3
    m["doubleSided"] = True
    m["extensions"] = {"KHR_materials_transmission": {"transmissionFactor": 0.5, "transmissionTexture": {"index": 0}},
                       "KHR_materials_ior": {"ior": 1.5},
                       "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1, 0.5, 0.5]},
                       "KHR_materials_volume": {"thicknessFactor": 0.1, "attenuationColor": [1, 0.5, 0.5],
                                                "attenuationDistance": 2}}
    put("gltf_scene", "textures.glb", glb(tex, buf + tiny_png))

    # Sparse accessor, strided view, quantized uint8 positions, triangle strip without indices.
    q = json.loads(json.dumps(base))
    qb = quad_buffer() + struct.pack("<2H", 1, 2) + struct.pack("<6f", 0, 1, 0, 0, 1, 0)
    q["bufferViews"] += [{"buffer": 0, "byteOffset": 140, "byteLength": 4}, {"buffer": 0, "byteOffset": 144, "byteLength": 24},
                         {"buffer": 0, "byteOffset": 0, "byteLength": 48, "byteStride": 12}]
    q["accessors"].append({"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                           "sparse": {"count": 2, "indices": {"bufferView": 4, "componentType": 5123},
                                      "values": {"bufferView": 5}}})
    q["accessors"].append({"bufferView": 6, "componentType": 5121, "normalized": True, "count": 4, "type": "VEC3"})
    q["meshes"].append({"primitives": [{"attributes": {"POSITION": 4}, "mode": 5},
                                       {"attributes": {"POSITION": 5, "COLOR_0": 1}, "mode": 6}]})
    q["extensionsUsed"] = ["KHR_mesh_quantization"]
    q["nodes"][2]["mesh"] = 1
    q["nodes"][2]["matrix"] = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]
    del q["nodes"][2]["translation"], q["nodes"][2]["rotation"], q["nodes"][2]["scale"]
    put("gltf_scene", "sparse_quantized.gltf", gltf(q, [qb]))

    # Edge cases: node hierarchy 50 deep, a node cycle, an out-of-range index, huge counts, NaNs.
    deep = json.loads(json.dumps(base))
    deep["nodes"] = [{"children": [i + 1]} for i in range(50)] + [{"mesh": 0}]
    deep["scenes"] = [{"nodes": [0]}]
    put("gltf_scene", "deep.gltf", gltf(deep, [quad_buffer()]))
    cyc = json.loads(json.dumps(base))
    cyc["nodes"] = [{"children": [1], "mesh": 0}, {"children": [0]}]
    cyc["scenes"] = [{"nodes": [0]}]
    put("gltf_scene", "cycle.gltf", gltf(cyc, [quad_buffer()]))
    bad = json.loads(json.dumps(base))
    bad["accessors"][3]["count"] = 1 << 30
    put("gltf_scene", "huge_count.gltf", gltf(bad, [quad_buffer()]))
    oob = json.loads(json.dumps(base))
    oob["meshes"][0]["primitives"][0]["indices"] = 7
    put("gltf_scene", "bad_index.gltf", gltf(oob, [quad_buffer()]))
    ortho = json.loads(json.dumps(base))
    ortho["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 2, "ymag": 2, "znear": 0.1, "zfar": 10}}]
    ortho["nodes"][0]["scale"] = [1e-10, 1e-10, 1e-10]
    put("gltf_scene", "ortho_tiny.gltf", gltf(ortho, [quad_buffer()]))
    # Hostile scales and depths: a camera node scaled by 2e19 (its frame's length overflowed float: NaN rays, an Embree
    # abort), an orthographic camera of xmag/ymag 1e19 (ray origins past Embree's bound), "extras"
    # nested 20,000 deep at the top level and in a node (a stack overflow in the JSON conversion),
    # and a texture transform of 3e38 (an infinite range buffer).
    scaled = json.loads(json.dumps(base))
    scaled["nodes"][1]["scale"] = [2e19, 2e19, 2e19]
    put("gltf_scene", "camera_scale_2e19.gltf", gltf(scaled, [quad_buffer()]))
    wide = json.loads(json.dumps(base))
    wide["cameras"] = [{"type": "orthographic", "orthographic": {"xmag": 1e19, "ymag": 1e19, "znear": 0.01, "zfar": 100}}]
    put("gltf_scene", "ortho_mag_1e19.gltf", gltf(wide, [quad_buffer()]))
    deep_json = "[" * 20000 + "]" * 20000
    for name, holder in (("deep_extras_top.gltf", None), ("deep_extras_node.gltf", 0)):
        doc = json.loads(json.dumps(base))
        (doc if holder is None else doc["nodes"][holder])["extras"] = "DEEP"
        put("gltf_scene", name, gltf(doc, [quad_buffer()]).replace('"DEEP"', deep_json))
    huge_transform = json.loads(json.dumps(tex))
    huge_transform["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"]["extensions"]["KHR_texture_transform"] = {
        "offset": [3e38, 3e38], "scale": [3e38, 3e38]}
    put("gltf_scene", "texture_transform_3e38.glb", glb(huge_transform, buf + tiny_png))
    nan = quad_buffer()
    nan = struct.pack("<3f", float("nan"), float("inf"), 3e38) + nan[12:]
    put("gltf_scene", "nan_positions.gltf", gltf(json.loads(json.dumps(base)), [nan]))
    put("gltf_scene", "minimal.gltf", '{"asset":{"version":"2.0"}}')
    put("gltf_scene", "external.gltf", json.dumps({"asset": {"version": "2.0"}, "buffers": [{"uri": "missing.bin", "byteLength": 8}],
                                                   "images": [{"uri": "missing.png"}]}))

    # The built-in cornell scene as one GLB, its two spheres (12k indices each) replaced by octahedra
    # so that the seed stays small enough for fast mutation; materials, nodes and camera as built.
    src = os.path.join(ROOT, "..", "assets", "cornell", "cornell.gltf")
    with open(src) as f:
        doc = json.load(f)
    with open(os.path.join(os.path.dirname(src), doc["buffers"][0]["uri"]), "rb") as f:
        old_bin = f.read()
    octa_pos = [(1, 0, 0), (-1, 0, 0), (0, 1, 0), (0, -1, 0), (0, 0, 1), (0, 0, -1)]
    octa_idx = [0, 2, 4, 2, 1, 4, 1, 3, 4, 3, 0, 4, 2, 0, 5, 1, 2, 5, 3, 1, 5, 0, 3, 5]
    sizes = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}
    comp = {5126: 4, 5125: 4, 5123: 2, 5121: 1}
    replaced = {}
    for mesh in doc["meshes"]:
        for prim in mesh["primitives"]:
            if doc["accessors"][prim["indices"]]["count"] <= 100:
                continue
            for sem, a in prim["attributes"].items():
                acc = doc["accessors"][a]
                n = sizes[acc["type"]]
                verts = octa_pos if sem == "NORMAL" else [(0.5,) * n] * 6
                if sem == "POSITION":  # the octahedron inscribed in the sphere's bounds
                    lo, hi = acc["min"], acc["max"]
                    verts = [tuple((lo[k] + hi[k]) / 2 + v[k] * (hi[k] - lo[k]) / 2 for k in range(3)) for v in octa_pos]
                replaced[a] = b"".join(struct.pack("<%df" % n, *v[:n]) for v in verts)
                acc["count"] = 6
            acc = doc["accessors"][prim["indices"]]
            acc["componentType"], acc["count"] = 5125, len(octa_idx)
            replaced[prim["indices"]] = struct.pack("<%dI" % len(octa_idx), *octa_idx)
    new_bin, views = b"", []
    for i, acc in enumerate(doc["accessors"]):
        if i in replaced:
            data = replaced[i]
        else:
            view = doc["bufferViews"][acc["bufferView"]]
            start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
            data = old_bin[start:start + acc["count"] * sizes[acc["type"]] * comp[acc["componentType"]]]
        new_bin += b"\0" * (-len(new_bin) % 4)
        views.append({"buffer": 0, "byteOffset": len(new_bin), "byteLength": len(data)})
        new_bin += data
        acc["bufferView"] = i
        acc.pop("byteOffset", None)
    doc["bufferViews"] = views
    del doc["buffers"]
    put("gltf_scene", "cornell_lowpoly.glb", glb(doc, new_bin))


png_seeds()
hdr_seeds()
exr_seeds()
gltf_seeds()
