#!/usr/bin/env python3
"""Mitsuba 3 scene of a Penumbra run, for cross-checking the pathtraced tier against an
independent renderer (docs/rendering.md, "Cross-check against Mitsuba 3").

Reads a run's output folder (composed.xml, the camera's intrinsics.json and frames.csv) and the
world file (lights, sky, material overrides, render settings) and builds the same scene as a
dict for mitsuba.load_dict:

  geometry   MuJoCo's compiled geoms (the mujoco package compiles composed.xml; poses at the
             model's initial state): box -> cube, sphere -> sphere, finite plane -> rectangle.
             groups > 2 and rgba alpha < 0.5 are invisible (as Penumbra). other shapes (capsule,
             cylinder, ellipsoid, mesh, height field), infinite planes, textures, mirror layers
             (reflectance > 0) and emissive planes are refused.
  materials  Penumbra's glTF 2.0 metallic-roughness BRDF (bsdf.h) has no
             built-in Mitsuba counterpart (Mitsuba's roughconductor / roughplastic /
             principled use exact Fresnel, uncorrelated Smith masking or a Disney diffuse), so
             it is registered here as a Mitsuba BSDF plugin ("penumbra_gltf"), written from the
             glTF 2.0 specification (appendix B): f = (1 - F) c_diff / pi + F D V, Schlick F
             with F0 = mix(0.08 specular, base, metallic), GGX D with alpha = roughness^2,
             height-correlated Smith V; two-sided. its sampling (cosine or GGX visible normals,
             an even mixture) is its own. MJCF materials map as Penumbra maps them: base =
             sRGB-decode(rgba), roughness = clamp(1 - shininess, 0.05, 1), specular, metallic 0,
             emission * base * 10000 / pi cd/m^2; the world's `materials:` overrides win.
  lights     units are Penumbra's (cd, lux, cd/m^2 per linear-sRGB channel): point lamp
             (radius 0) -> point, intensity I color; lamp of radius r -> a black sphere with an
             area emitter of radiance I color / (pi r^2); spot with inner = outer -> spot (hard
             cone); directional, and sun with angular_diameter_deg 0 -> directional, irradiance
             E color. refused: soft spot edges (Penumbra's smoothstep in cos is not Mitsuba's
             ramp), sun discs (no disc emitter), cast_shadow false, lights attached to bodies,
             MJCF <light>s.
  sky        uniform -> constant emitter, radiance = color luminance_cd_m2; the Preetham
             daylight sky is refused (Mitsuba has none; its sunsky is Hosek-Wilkie).
  camera     pinhole from intrinsics.json (fx = fy, principal point at the image centre) and
             the optical frame's pose in frames.csv; box pixel filter (Penumbra jitters each
             sample uniformly over its pixel); path integrator with max_depth = max_bounces + 1
             (Penumbra's next-event estimation at vertices 0 .. max_bounces - 1, emitters met
             at vertex max_bounces still count).

Output: linear radiance in cd/m^2 per channel, no exposure, no tone map.

usage: mitsuba_export.py RUN_DIR [--world WORLD.yaml] [--camera NAME] [--frame N]
                         [--spp N] [--variant llvm_ad_rgb] [--out image.exr|image.npy]
                         [--print-dict]
"""

import argparse
import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

MJCF_MIN_ROUGHNESS = 0.05  # physics/scene_extractor.h, kMjcfMinRoughness
MJCF_EMISSION_LUMINANCE = 10000.0 / math.pi  # kMjcfEmissionLuminance, cd/m^2
INFINITE_PLANE_REFUSED = "an infinite plane (size 0)"


class ExportError(Exception):
    """a part of the world Mitsuba cannot express exactly."""


def srgb_to_linear(c):
    c = float(c)
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055)**2.4


def load_world(path):
    from ruamel.yaml import YAML
    with open(path) as f:
        return YAML(typ="safe").load(f) or {}


def set_variant(variant=None):
    import mitsuba as mi
    if variant is None:
        variant = "llvm_ad_rgb" if "llvm_ad_rgb" in mi.variants() else "scalar_rgb"
    try:
        mi.set_variant(variant)
    except Exception:  # no llvm on this machine
        mi.set_variant("scalar_rgb")
    register_gltf_bsdf()
    return mi.variant()


# --------------------------------------------------------------------------------------------
# the glTF 2.0 metallic-roughness BRDF as a Mitsuba BSDF

_registered = set()


def register_gltf_bsdf():
    import drjit as dr
    import mitsuba as mi
    if mi.variant() in _registered:
        return
    inv_pi = 1.0 / math.pi

    class GltfBsdf(mi.BSDF):
        """f(wi, wo) = (1 - F) c_diff / pi + F D V (glTF 2.0 appendix B), two-sided."""

        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.c_diff = mi.Color3f(props["c_r"], props["c_g"], props["c_b"])
            self.f0 = mi.Color3f(props["f0_r"], props["f0_g"], props["f0_b"])
            self.alpha = float(props["alpha"])
            has_diffuse = max(props["c_r"], props["c_g"], props["c_b"]) > 0
            self.p_spec = 0.5 if has_diffuse else 1.0
            both = mi.BSDFFlags.FrontSide | mi.BSDFFlags.BackSide
            self.m_components = [mi.BSDFFlags.DiffuseReflection | both,
                                 mi.BSDFFlags.GlossyReflection | both]
            self.m_flags = self.m_components[0] | self.m_components[1]

        def _local(self, si, wo):
            # mirror both directions below the surface (two-sided, as Penumbra's ng faces wo)
            s = dr.select(mi.Frame3f.cos_theta(si.wi) < 0, -1.0, 1.0)
            wi = mi.Vector3f(si.wi.x, si.wi.y, si.wi.z * s)
            wl = mi.Vector3f(wo.x, wo.y, wo.z * s)
            return wi, wl, s

        def _value_pdf(self, wv, wl):
            # wv: towards the viewer, wl: towards the light (local, upper hemisphere)
            a = self.alpha
            a2 = a * a
            n_v, n_l = wv.z, wl.z
            valid = (n_v > 0) & (n_l > 0)
            h = dr.normalize(wv + wl)
            v_h = dr.maximum(dr.dot(wv, h), 0.0)
            m = dr.clip(1.0 - v_h, 0.0, 1.0)
            m5 = m * m * m * m * m
            F = self.f0 + (1.0 - self.f0) * m5
            k = (a2 - 1.0) * h.z * h.z + 1.0
            D = a2 / (dr.pi * k * k)
            V = 0.5 / (n_l * dr.sqrt(n_v * n_v * (1.0 - a2) + a2) +
                       n_v * dr.sqrt(n_l * n_l * (1.0 - a2) + a2))
            f = (1.0 - F) * self.c_diff * inv_pi + F * (D * V)
            distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, a, True)
            pdf_spec = distr.pdf(wv, h) / (4.0 * dr.dot(wl, h))
            pdf = (1.0 - self.p_spec) * n_l * inv_pi + self.p_spec * pdf_spec
            value = dr.select(valid, f * n_l, 0.0)
            pdf = dr.select(valid & (pdf > 0), pdf, 0.0)
            return value, pdf

        def eval(self, ctx, si, wo, active=True):
            wv, wl, _ = self._local(si, wo)
            return self._value_pdf(wv, wl)[0]

        def pdf(self, ctx, si, wo, active=True):
            wv, wl, _ = self._local(si, wo)
            return self._value_pdf(wv, wl)[1]

        def eval_pdf(self, ctx, si, wo, active=True):
            wv, wl, _ = self._local(si, wo)
            return self._value_pdf(wv, wl)

        def sample(self, ctx, si, sample1, sample2, active=True):
            wv, _, s = self._local(si, si.wi)
            distr = mi.MicrofacetDistribution(mi.MicrofacetType.GGX, self.alpha, True)
            spec = sample1 < self.p_spec
            m_h, _ = distr.sample(wv, sample2)
            wl_spec = 2.0 * dr.dot(wv, m_h) * m_h - wv
            wl_diff = mi.warp.square_to_cosine_hemisphere(sample2)
            wl = dr.select(spec, wl_spec, wl_diff)
            value, pdf = self._value_pdf(wv, wl)
            bs = dr.zeros(mi.BSDFSample3f)
            bs.wo = mi.Vector3f(wl.x, wl.y, wl.z * s)
            bs.pdf = pdf
            bs.eta = 1.0
            bs.sampled_component = dr.select(spec, mi.UInt32(1), mi.UInt32(0))
            bs.sampled_type = dr.select(spec, mi.UInt32(+mi.BSDFFlags.GlossyReflection),
                                        mi.UInt32(+mi.BSDFFlags.DiffuseReflection))
            ok = active & (pdf > 0) & (wl.z > 0)
            return bs, dr.select(ok, value / dr.maximum(pdf, 1e-30), 0.0)

        def traverse(self, callback):
            pass

        def parameters_changed(self, keys):
            pass

        def to_string(self):
            return f"PenumbraGltf[alpha={self.alpha}]"

    mi.register_bsdf("penumbra_gltf", lambda props: GltfBsdf(props))
    _registered.add(mi.variant())


# --------------------------------------------------------------------------------------------
# materials


def gltf_coefficients(base, roughness, metallic, specular):
    """c_diff, f0 and alpha of Penumbra's BRDF from material parameters (clamped to range)."""
    metallic = min(max(metallic, 0.0), 1.0)
    base = [min(max(c, 0.0), 1.0) for c in base]
    r = min(max(roughness, 0.0), 1.0)
    alpha = max(r * r, 1e-3)
    f0d = 0.08 * min(max(specular, 0.0), 1.0)
    f0 = [f0d + (c - f0d) * metallic for c in base]
    c_diff = [c * (1.0 - metallic) for c in base]
    return c_diff, f0, alpha


def mjcf_material(model, mat_id, geom_rgba):
    """Penumbra's material of a geom (physics/scene_extractor.h's mapping) as a dict."""
    default_rgba = np.array([0.5, 0.5, 0.5, 1.0], np.float32)
    use_material = mat_id >= 0 and np.array_equal(geom_rgba.astype(np.float32), default_rgba)
    if mat_id >= 0:
        rgba = model.mat_rgba[mat_id] if use_material else geom_rgba
        m = dict(specular=float(model.mat_specular[mat_id]),
                 shininess=float(model.mat_shininess[mat_id]),
                 reflectance=float(model.mat_reflectance[mat_id]),
                 emission=float(model.mat_emission[mat_id]),
                 texture=int(max(model.mat_texid[mat_id])) if model.mat_texid.size else -1)
        name = model.material(mat_id).name
    else:
        rgba = geom_rgba
        m = dict(specular=0.5, shininess=0.5, reflectance=0.0, emission=0.0, texture=-1)
        name = None
    base = [srgb_to_linear(c) for c in rgba[:3]]
    return dict(name=name, base_color=base, alpha=float(rgba[3]),
                roughness=min(max(1.0 - m["shininess"], MJCF_MIN_ROUGHNESS), 1.0), metallic=0.0,
                specular=min(max(m["specular"], 0.0), 1.0), reflectance=m["reflectance"],
                emission=[c * max(m["emission"], 0.0) * MJCF_EMISSION_LUMINANCE for c in base],
                texture=m["texture"])


def apply_override(mat, overrides):
    o = overrides.get(mat["name"]) if mat["name"] else None
    if not o:
        return mat
    mat = dict(mat)
    for key in ("base_color", "roughness", "metallic", "specular", "emission"):
        if key in o:
            mat[key] = o[key]
    if "procedural" in o:
        raise ExportError(f"material {mat['name']}: procedural maps are not exported")
    return mat


def bsdf_of(mat):
    c_diff, f0, alpha = gltf_coefficients(mat["base_color"], mat["roughness"], mat["metallic"],
                                          mat["specular"])
    return {"type": "penumbra_gltf", "c_r": c_diff[0], "c_g": c_diff[1], "c_b": c_diff[2],
            "f0_r": f0[0], "f0_g": f0[1], "f0_b": f0[2], "alpha": alpha}


# --------------------------------------------------------------------------------------------
# the scene


def _matrix(R, t, scale=(1.0, 1.0, 1.0)):
    import mitsuba as mi
    M = np.eye(4)
    M[:3, :3] = np.asarray(R) @ np.diag(scale)
    M[:3, 3] = t
    return mi.ScalarTransform4f(M.tolist())


def _rgb(v):
    return {"type": "rgb", "value": [float(x) for x in v]}


def geometry(run_dir, overrides):
    """the shapes of composed.xml's visible geoms, keyed by geom name."""
    import mujoco
    model = mujoco.MjModel.from_xml_path(str(Path(run_dir) / "composed.xml"))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    if model.nlight > 0:
        raise ExportError("composed.xml has MJCF <light>s: not exported (use world-file lights)")
    shapes = {}
    G = mujoco.mjtGeom
    for g in range(model.ngeom):
        name = model.geom(g).name or f"geom{g}"
        mat = apply_override(mjcf_material(model, int(model.geom_matid[g]), model.geom_rgba[g]),
                             overrides)
        if model.geom_group[g] > 2 or mat["alpha"] < 0.5:
            continue
        if mat["texture"] >= 0:
            raise ExportError(f"geom {name}: textured materials are not exported")
        if mat["reflectance"] > 0:
            raise ExportError(f"geom {name}: a mirror layer (reflectance > 0) is not exported")
        R = data.geom_xmat[g].reshape(3, 3)
        t = data.geom_xpos[g]
        size = model.geom_size[g]
        kind = model.geom_type[g]
        emissive = max(mat["emission"]) > 0
        if kind == G.mjGEOM_BOX:
            shape = {"type": "cube", "to_world": _matrix(R, t, size)}
        elif kind == G.mjGEOM_SPHERE:
            shape = {"type": "sphere", "to_world": _matrix(R, t, [size[0]] * 3)}
        elif kind == G.mjGEOM_PLANE:
            if not (size[0] > 0 and size[1] > 0):
                raise ExportError(f"geom {name}: {INFINITE_PLANE_REFUSED} is not exported")
            if emissive:
                raise ExportError(f"geom {name}: an emissive plane (one-sided in Mitsuba)")
            shape = {"type": "rectangle", "to_world": _matrix(R, t, [size[0], size[1], 1.0])}
        else:
            raise ExportError(f"geom {name}: type {G(kind).name} is not exported "
                              "(box, sphere and finite plane only)")
        shape["bsdf"] = bsdf_of(mat)
        if emissive:
            shape["emitter"] = {"type": "area", "radiance": _rgb(mat["emission"])}
        shapes["geom_" + name.replace("/", "_")] = shape
    return shapes


def lights_and_sky(world, light_scale=1.0):
    """emitters of the world's lights (each scaled by light_scale) and of its sky."""
    out = {}
    for i, l in enumerate(world.get("lights") or []):
        name = l.get("name", f"light{i}")
        kind = l.get("type", "point")
        color = np.array(l.get("color", [1, 1, 1]), float).clip(0, None) * light_scale
        if l.get("attach", "world") != "world":
            raise ExportError(f"light {name}: attached to a body; only world lights are exported")
        if not l.get("cast_shadow", True):
            raise ExportError(f"light {name}: cast_shadow false has no Mitsuba counterpart")
        if kind in ("sun", "directional"):
            if kind == "sun" and float(l.get("angular_diameter_deg", 0.53)) > 0:
                raise ExportError(f"light {name}: a sun disc (angular_diameter_deg > 0) has no "
                                  "Mitsuba counterpart; use angular_diameter_deg: 0")
            d = np.array(l.get("direction", [0, 0, -1]), float)
            out["light_" + name] = {"type": "directional",
                                    "direction": (d / np.linalg.norm(d)).tolist(),
                                    "irradiance": _rgb(color * float(l["illuminance_lux"]))}
            continue
        I = float(l["intensity_cd"]) if "intensity_cd" in l else 683.0 * float(
            l["power_w"]) / (4 * math.pi)
        p = [float(x) for x in l.get("position", [0, 0, 3])]
        r = float(l.get("radius_m", 0.0))
        if kind == "spot":
            inner, outer = float(l.get("inner_angle_deg", 30)), float(l.get("outer_angle_deg", 45))
            if inner != outer:
                raise ExportError(f"light {name}: a soft spot edge (inner < outer) differs from "
                                  "Mitsuba's spot falloff; set inner_angle_deg = outer_angle_deg")
            if r > 0:
                raise ExportError(f"light {name}: a spot with a radius is not exported")
            d = np.array(l.get("direction", [0, 0, -1]), float)
            import mitsuba as mi
            out["light_" + name] = {
                "type": "spot", "intensity": _rgb(color * I), "cutoff_angle": outer,
                "beam_width": outer,
                "to_world": mi.ScalarTransform4f().look_at(
                    origin=p, target=(np.array(p) + d).tolist(),
                    up=[0, 0, 1] if abs(d[2]) < 0.99 else [1, 0, 0])}
        elif kind == "point" and r > 0:
            out["light_" + name] = {
                "type": "sphere", "center": p, "radius": r,
                "bsdf": {"type": "diffuse", "reflectance": _rgb([0, 0, 0])},
                "emitter": {"type": "area", "radiance": _rgb(color * I / (math.pi * r * r))}}
        elif kind == "point":
            out["light_" + name] = {"type": "point", "position": p, "intensity": _rgb(color * I)}
        else:
            raise ExportError(f"light {name}: type {kind} is not exported")
    sky = world.get("sky") or {}
    if sky.get("type", "uniform") != "uniform":
        raise ExportError("sky: the daylight (Preetham) sky has no Mitsuba counterpart; "
                          "use a uniform sky")
    radiance = np.array(sky.get("color", [0.6, 0.7, 0.8]), float) * float(
        sky.get("luminance_cd_m2", 1000))
    if radiance.max() > 0:
        out["sky"] = {"type": "constant", "radiance": _rgb(radiance)}
    return out


def camera(run_dir, name, frame, spp, seed=0):
    import mitsuba as mi
    cam_dir = Path(run_dir) / name
    if not (cam_dir / "intrinsics.json").is_file():
        raise ExportError(f"camera {name}: no {cam_dir}/intrinsics.json (not this world's run?)")
    k = json.loads((cam_dir / "intrinsics.json").read_text())
    w, h = int(k["width"]), int(k["height"])
    if abs(k["fx"] - k["fy"]) > 1e-9 * k["fx"] or abs(k["cx"] - (w - 1) / 2) > 1e-9 or abs(
            k["cy"] - (h - 1) / 2) > 1e-9:
        raise ExportError(f"camera {name}: only square pixels and a centred principal point")
    if k.get("model", "pinhole") != "pinhole":
        raise ExportError(f"camera {name}: lens distortion is not exported")
    with open(cam_dir / "frames.csv") as f:
        rows = [r for r in csv.DictReader(f) if int(r["frame"]) == frame]
    if not rows:
        raise ExportError(f"camera {name}: no frame {frame} in frames.csv")
    r = rows[0]
    # the optical frame (x right, y down, z forward) in the world, from its unit quaternion
    x, y, z, s = (float(r[c]) for c in ("qx", "qy", "qz", "qw"))
    R_opt = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * s), 2 * (x * z + y * s)],
                      [2 * (x * y + z * s), 1 - 2 * (x * x + z * z), 2 * (y * z - x * s)],
                      [2 * (x * z - y * s), 2 * (y * z + x * s), 1 - 2 * (x * x + y * y)]])
    # mitsuba's camera frame: x left, y up, z forward; the optical frame: x right, y down
    R = R_opt @ np.diag([-1.0, -1.0, 1.0])
    t = [float(r["x"]), float(r["y"]), float(r["z"])]
    fovy = math.degrees(2 * math.atan(h / 2 / k["fy"]))
    return {
        "type": "perspective", "fov_axis": "y", "fov": fovy, "near_clip": 0.01,
        "far_clip": 1e5, "to_world": _matrix(R, t),
        "sampler": {"type": "independent", "sample_count": int(spp), "seed": int(seed)},
        "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"},
                 "pixel_format": "rgb", "component_format": "float32"},
    }


def build_scene(run_dir, world_path=None, camera_name=None, frame=0, spp=1024, seed=0,
                light_scale=1.0):
    """the Mitsuba scene dict of camera `camera_name` (default: the run's only camera) at
    frame `frame` of the run in run_dir, every world light scaled by light_scale (1: as the
    world says); raises ExportError for what does not map."""
    run_dir = Path(run_dir)
    if world_path is None:
        world_path = json.loads((run_dir / "run.json").read_text())["world_file"]
    world = load_world(world_path)
    if camera_name is None:
        cams = [c["name"] for c in world.get("cameras") or []]
        if len(cams) != 1:
            raise ExportError(f"name the camera (--camera): the world has {cams}")
        camera_name = cams[0]
    render = world.get("render") or {}
    scene = {"type": "scene",
             "integrator": {"type": "path", "max_depth": int(render.get("max_bounces", 4)) + 1},
             "sensor": camera(run_dir, camera_name, frame, spp, seed)}
    scene.update(geometry(run_dir, world.get("materials") or {}))
    scene.update(lights_and_sky(world, light_scale))
    return scene


def render(scene_dict, spp=None, seed=0):
    """linear radiance (H x W x 3 float64, cd/m^2 per channel) of a scene dict."""
    import mitsuba as mi
    scene = mi.load_dict(scene_dict)
    img = mi.render(scene, spp=spp, seed=seed)
    return np.array(img, dtype=np.float64)[..., :3]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("run_dir")
    ap.add_argument("--world", help="world file (default: run.json's world_file)")
    ap.add_argument("--camera")
    ap.add_argument("--frame", type=int, default=0)
    ap.add_argument("--spp", type=int, default=1024)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--variant", default=None, help="llvm_ad_rgb (default where it runs) or "
                    "scalar_rgb")
    ap.add_argument("--out", help="write the linear radiance: .exr (Mitsuba's writer) or .npy")
    ap.add_argument("--print-dict", action="store_true", help="print the scene dict")
    a = ap.parse_args()
    variant = set_variant(a.variant)
    try:
        scene = build_scene(a.run_dir, a.world, a.camera, a.frame, a.spp, a.seed)
    except ExportError as e:
        print(f"mitsuba_export: {e}", file=sys.stderr)
        return 2
    if a.print_dict:
        for k, v in scene.items():
            print(f"{k}: {v}")
    if a.out:
        img = render(scene, a.spp, a.seed)
        if a.out.endswith(".npy"):
            np.save(a.out, img)
        else:
            import mitsuba as mi
            mi.Bitmap(img.astype(np.float32)).write(a.out)
        print(f"{a.out}: {img.shape[1]}x{img.shape[0]}, {a.spp} spp ({variant}), mean radiance "
              f"{img.reshape(-1, 3).mean(0).round(4).tolist()} cd/m^2")
    return 0


if __name__ == "__main__":
    sys.exit(main())
