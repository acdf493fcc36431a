"""pxf against Blender Cycles on the same glTF: rough glass and multiscatter rough metal.

Two modes, driven by scripts/cycles_compare.sh:
  python3 scripts/cycles_compare.py scene CASE DIR
      writes DIR/scene.gltf (a sphere of the case's material on a Lambert floor, a camera) and
      DIR/white.hdr (a uniform environment of radiance 1).
  blender -b --python scripts/cycles_compare.py -- render CASE DIR SPP
      imports DIR/scene.gltf, gives each material the Cycles BSDF that matches pxf's, lights the scene
      with the same uniform white world, renders DIR/cycles.exr at SPP samples (no clamping, no
      glossy filter, box pixel filter, 64 bounces, no denoising), and compares DIR/pxf/final.exr
      with it: the image means and the NRMSE of 16x16-block means, in % of the Cycles mean.

The materials (glTF roughness r, GGX alpha = r^2 in both renderers):
  glass-0.1, glass-0.3: KHR_materials_transmission 1, ior 1.5, alpha 0.1 / 0.3; in Cycles a Glass
      BSDF with GGX (single scattering, as pxf's Walter et al. BSDF, docs/materials.md; Cycles 3.x
      splits reflection and refraction by the Fresnel of the macro normal, pxf by each microfacet's,
      so DIR/pxf-cycles-fresnel/final.exr, from a build with Cycles' split, is compared too).
  metal-0.49: metallic 1, base colour (0.95, 0.64, 0.54), alpha 0.49; in Cycles the Principled BSDF
      with Multiscatter GGX (pxf compensates the lost energy, Turquin 2019).
The floor: base colour 0.5 with KHR_materials_specular 0 (pure Lambert in pxf); in Cycles a Diffuse
BSDF of 0.5.
"""
import base64
import json
import math
import os
import struct
import sys

CASES = {
    "glass-0.1": dict(kind="glass", alpha=0.1),
    "glass-0.3": dict(kind="glass", alpha=0.3),
    "metal-0.49": dict(kind="metal", alpha=0.49, color=(0.95, 0.64, 0.54)),
}
FLOOR_ALBEDO = 0.5
SIZE = 128


def sphere_mesh(radius, centre, rings=48, segments=96):
    positions, normals, indices = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2.0 * math.pi * j / segments
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), math.sin(theta) * math.sin(phi))
            normals.append(n)
            positions.append(tuple(centre[k] + radius * n[k] for k in range(3)))
    for i in range(rings):
        for j in range(segments):
            a = i * (segments + 1) + j
            b = a + segments + 1
            if i > 0:  # the pole rows' first triangles have no area
                indices += [a, a + 1, b]
            if i < rings - 1:
                indices += [b, a + 1, b + 1]
    return positions, normals, indices


def floor_mesh(half):
    positions = [(-half, 0.0, -half), (half, 0.0, -half), (half, 0.0, half), (-half, 0.0, half)]
    return positions, [(0.0, 1.0, 0.0)] * 4, [0, 2, 1, 0, 3, 2]


def material_json(case):
    c = CASES[case]
    roughness = math.sqrt(c["alpha"])
    if c["kind"] == "glass":
        return {"name": "test", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.0,
                                                          "roughnessFactor": roughness},
                "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                               "KHR_materials_ior": {"ior": 1.5}}}
    return {"name": "test", "pbrMetallicRoughness": {"baseColorFactor": list(c["color"]) + [1], "metallicFactor": 1.0,
                                                      "roughnessFactor": roughness}}


def write_scene(case, out):
    os.makedirs(out, exist_ok=True)
    blob = bytearray()
    accessors, views, meshes = [], [], []

    def add(data, fmt, count, gltf_type, component, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        offset = len(blob)
        for item in data:
            blob.extend(struct.pack(fmt, *item) if isinstance(item, tuple) else struct.pack(fmt, item))
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(blob) - offset, "target": target})
        accessor = {"bufferView": len(views) - 1, "componentType": component, "count": count, "type": gltf_type}
        if minmax:
            accessor["min"], accessor["max"] = minmax
        accessors.append(accessor)
        return len(accessors) - 1

    for name, (positions, normals, indices), material in (
            ("sphere", sphere_mesh(0.5, (0.0, 0.5, 0.0)), 0), ("floor", floor_mesh(4.0), 1)):
        lo = [min(p[k] for p in positions) for k in range(3)]
        hi = [max(p[k] for p in positions) for k in range(3)]
        pos = add(positions, "<3f", len(positions), "VEC3", 5126, 34962, (lo, hi))
        nrm = add(normals, "<3f", len(normals), "VEC3", 5126, 34962)
        idx = add(indices, "<I", len(indices), "SCALAR", 5125, 34963)
        meshes.append({"name": name, "primitives": [{"attributes": {"POSITION": pos, "NORMAL": nrm}, "indices": idx,
                                                     "material": material}]})
    tilt = math.radians(-12.0)  # the camera looks down a little, along -z of its node
    gltf = {
        "asset": {"version": "2.0", "generator": "pxf scripts/cycles_compare.py"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_specular"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2]}],
        "nodes": [{"mesh": 0}, {"mesh": 1},
                  {"camera": 0, "translation": [0.0, 1.2, 3.2],
                   "rotation": [math.sin(tilt / 2), 0.0, 0.0, math.cos(tilt / 2)]}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": math.radians(30.0), "aspectRatio": 1.0,
                                                            "znear": 0.01, "zfar": 100.0}}],
        "meshes": meshes,
        "materials": [material_json(case),
                      {"name": "floor", "pbrMetallicRoughness": {"baseColorFactor": [FLOOR_ALBEDO] * 3 + [1],
                                                                  "metallicFactor": 0.0, "roughnessFactor": 1.0},
                       "extensions": {"KHR_materials_specular": {"specularFactor": 0.0}}}],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": len(blob),
                     "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(blob)).decode()}],
    }
    with open(os.path.join(out, "scene.gltf"), "w") as f:
        json.dump(gltf, f)
    # Radiance RGBE of 1.0 is (128, 128, 128, 129): mantissa 0.5, exponent 1.
    with open(os.path.join(out, "white.hdr"), "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y 4 +X 8\n" + bytes([128, 128, 128, 129]) * 32)


def render_and_compare(case, out, spp):
    import bpy
    import numpy as np

    if not hasattr(np, "bool"):
        np.bool = bool  # Debian's Blender 3.4 glTF importer still uses the alias NumPy 1.24 removed
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=os.path.join(out, "scene.gltf"))
    scene = bpy.context.scene
    scene.camera = next(o for o in scene.objects if o.type == "CAMERA")
    c = CASES[case]
    for mat in bpy.data.materials:
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
        if mat.name == "floor":
            bsdf = nodes.new("ShaderNodeBsdfDiffuse")
            bsdf.inputs["Color"].default_value = (FLOOR_ALBEDO, FLOOR_ALBEDO, FLOOR_ALBEDO, 1.0)
            bsdf.inputs["Roughness"].default_value = 0.0  # Lambert
        elif c["kind"] == "glass":
            bsdf = nodes.new("ShaderNodeBsdfGlass")
            bsdf.distribution = "GGX"
            bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
            bsdf.inputs["Roughness"].default_value = math.sqrt(c["alpha"])
            bsdf.inputs["IOR"].default_value = 1.5
        else:
            bsdf = nodes.new("ShaderNodeBsdfPrincipled")
            bsdf.distribution = "MULTI_GGX"
            bsdf.inputs["Base Color"].default_value = tuple(c["color"]) + (1.0,)
            bsdf.inputs["Metallic"].default_value = 1.0
            bsdf.inputs["Roughness"].default_value = math.sqrt(c["alpha"])
        links.new(bsdf.outputs[0], output.inputs["Surface"])
    world = bpy.data.worlds.new("white")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0
    scene.world = world
    scene.render.engine = "CYCLES"
    cy = scene.cycles
    cy.device = "CPU"
    cy.samples = spp
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = cy.transmission_bounces = 64
    cy.transparent_max_bounces = 64
    cy.sample_clamp_direct = 0.0
    cy.sample_clamp_indirect = 0.0
    cy.blur_glossy = 0.0
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.seed = 7
    scene.render.resolution_x = scene.render.resolution_y = SIZE
    scene.render.resolution_percentage = 100
    scene.render.film_transparent = False
    scene.view_settings.view_transform = "Standard"
    scene.render.image_settings.file_format = "OPEN_EXR"
    scene.render.image_settings.color_depth = "32"
    scene.render.filepath = os.path.join(out, "cycles.exr")
    bpy.ops.render.render(write_still=True)

    def load(path):
        image = bpy.data.images.load(path)
        pixels = np.array(image.pixels[:], dtype=np.float64).reshape(image.size[1], image.size[0], 4)[:, :, :3]
        return pixels

    cycles = load(os.path.join(out, "cycles.exr"))
    compare(case, out, cycles, load(os.path.join(out, "pxf", "final.exr")), "pxf", "compare.png")
    # The glass cases again, from the build with Cycles 3.x's Fresnel split (scripts/cycles_compare.sh).
    variant = os.path.join(out, "pxf-cycles-fresnel", "final.exr")
    if os.path.exists(variant):
        compare(case, out, cycles, load(variant), "pxf with Cycles' glass Fresnel", "compare-cycles-fresnel.png")


def compare(case, out, cycles, pxf, label, picture_name):
    import bpy
    import numpy as np
    if cycles.shape != pxf.shape:
        sys.exit("sizes differ: cycles %s, pxf %s" % (cycles.shape, pxf.shape))
    mean_c, mean_p = cycles.mean(), pxf.mean()
    blocks = lambda a: a.reshape(SIZE // 16, 16, SIZE // 16, 16, 3).mean(axis=(1, 3))
    block_nrmse = math.sqrt(((blocks(pxf) - blocks(cycles)) ** 2).mean()) / mean_c
    # pxf, Cycles and their difference (red: pxf brighter, blue: darker, x10), as DIR/compare.png.
    shown = lambda a: np.clip(a / (1.0 + a), 0.0, 1.0) ** (1.0 / 2.2)
    diff = np.clip(10.0 * (pxf - cycles).mean(axis=2, keepdims=True), -1.0, 1.0)
    signed = np.concatenate([np.maximum(diff, 0.0), np.zeros_like(diff), np.maximum(-diff, 0.0)], axis=2)
    strip = np.concatenate([shown(pxf), shown(cycles), signed], axis=1)
    picture = bpy.data.images.new("compare", strip.shape[1], strip.shape[0], alpha=False)
    picture.pixels[:] = np.concatenate([strip, np.ones(strip.shape[:2] + (1,))], axis=2).ravel()
    picture.filepath_raw = os.path.join(out, picture_name)
    picture.file_format = "PNG"
    picture.save()
    print("CYCLES-COMPARE %s, %s: mean %.5f, cycles %.5f (ratio %.4f); 16x16-block NRMSE %.2f %%"
          % (case, label, mean_p, mean_c, mean_p / mean_c, 100.0 * block_nrmse))


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else sys.argv[1:]
    if len(args) >= 3 and args[0] == "scene" and args[1] in CASES:
        write_scene(args[1], args[2])
    elif len(args) >= 4 and args[0] == "render" and args[1] in CASES:
        render_and_compare(args[1], args[2], int(args[3]))
    else:
        sys.exit("usage: cycles_compare.py scene CASE DIR | blender -b --python cycles_compare.py -- render CASE DIR SPP; "
                 "CASE: " + ", ".join(CASES))
