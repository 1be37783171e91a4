"""Clear skies of three published families, alone (no scene), as daylit env maps: the independent
computation that sky/'s re-aiming is held to (sky/sky_family_test.cc, docs/sky.md).

    blender -b --factory-startup --python scenes/skies.py -- --out DIR [--size 360x180] [--samples 16]

Blender 3.4's sky textures: Nishita (single scattering with air, dust and ozone; sun disc off),
Hosek-Wilkie (2012) and Preetham (1999), each at two hazes and five sun elevations (the sun at
scene azimuth 30 deg), rendered with an equirectangular camera in daylit's env-map convention (row
0 the zenith, the centre column along +Y, right toward +X; docs/recording-format.md) and written as
half-float EXR, FAMILY_HAZE_elEE.exr, plus skies.json (each file's family, haze and sun).
A world-only render: every sample is the texture itself, so 16 samples only antialias.
"""
import argparse
import json
import math
import os
import sys

import bpy
from mathutils import Vector

ELEVATIONS = [10, 20, 35, 50, 70]
AZIMUTH = 30.0
SKIES = [
    ("nishita", "dust1", {"type": "NISHITA", "dust": 1.0}),
    ("nishita", "dust5", {"type": "NISHITA", "dust": 5.0}),
    ("hosek", "t2", {"type": "HOSEK_WILKIE", "turbidity": 2.0}),
    ("hosek", "t4", {"type": "HOSEK_WILKIE", "turbidity": 4.0}),
    ("preetham", "t2.5", {"type": "PREETHAM", "turbidity": 2.5}),
    ("preetham", "t4", {"type": "PREETHAM", "turbidity": 4.0}),
]


def args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", required=True)
    ap.add_argument("--size", default="360x180")
    ap.add_argument("--samples", type=int, default=16)
    return ap.parse_args(argv)


def main():
    a = args()
    w, h = (int(x) for x in a.size.split("x"))
    os.makedirs(a.out, exist_ok=True)
    s = bpy.context.scene
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o, do_unlink=True)
    s.render.engine = "CYCLES"
    s.cycles.device = "CPU"
    s.cycles.samples = a.samples
    s.cycles.use_denoising = False
    s.render.resolution_x, s.render.resolution_y = w, h
    s.render.resolution_percentage = 100
    s.view_settings.view_transform = "Standard"
    s.view_settings.exposure = 0.0
    cd = bpy.data.cameras.new("pano")
    cd.type = "PANO"
    cd.cycles.panorama_type = "EQUIRECTANGULAR"
    cd.cycles.latitude_min, cd.cycles.latitude_max = -math.pi / 2, math.pi / 2
    cd.cycles.longitude_min, cd.cycles.longitude_max = -math.pi, math.pi
    cam = bpy.data.objects.new("pano", cd)
    s.collection.objects.link(cam)
    cam.rotation_mode = "XYZ"
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)  # centre along +Y, right = +X
    s.camera = cam
    world = bpy.data.worlds.new("sky")
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    sky = nt.nodes.new("ShaderNodeTexSky")
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(sky.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    s.world = world
    st = s.render.image_settings
    st.file_format = "OPEN_EXR"
    st.color_mode = "RGB"
    st.color_depth = "16"
    st.exr_codec = "ZIP"
    index = []
    for family, haze, p in SKIES:
        for el in ELEVATIONS:
            sky.sky_type = p["type"]
            az = math.radians(AZIMUTH)
            d = Vector((math.sin(az) * math.cos(math.radians(el)), math.cos(az) * math.cos(math.radians(el)),
                        math.sin(math.radians(el))))
            if p["type"] == "NISHITA":
                sky.sun_disc = False
                sky.sun_elevation = math.radians(el)
                sky.sun_rotation = az  # as the generator sets it: the scene azimuth (from +Y toward +X)
                sky.altitude = 0.0
                sky.air_density, sky.dust_density, sky.ozone_density = 1.0, p["dust"], 1.0
            else:
                sky.sun_direction = d
                sky.turbidity = p["turbidity"]
                if p["type"] == "HOSEK_WILKIE":
                    sky.ground_albedo = 0.3
            name = "%s_%s_el%02d.exr" % (family, haze, el)
            bpy.ops.render.render(write_still=False)
            bpy.data.images["Render Result"].save_render(filepath=os.path.join(a.out, name), scene=s)
            index.append({"file": name, "family": family, "haze": haze, "sun_elevation_deg": el,
                          "sun_azimuth_scene_deg": AZIMUTH, "sun_dir": [d.x, d.y, d.z]})
            print("sky", name, flush=True)
    with open(os.path.join(a.out, "skies.json"), "w") as fh:
        json.dump({"size": [w, h], "samples": a.samples, "skies": index}, fh, indent=1)


main()
