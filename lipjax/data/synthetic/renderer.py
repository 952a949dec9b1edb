"""The frame renderer: visibility, surfaces, lighting (shadows, gloss, haze, sky, optional floor reflections), then
the camera model."""
from __future__ import annotations

import dataclasses

import cv2
import numpy as np

from lipjax.data.frame import Intrinsics
from lipjax.data.synthetic.arrays import _cols, _set_cols
from lipjax.data.synthetic.camera import _camera_image
from lipjax.data.synthetic.constants import _F32, _FLOOR, _ROAD, _TERRAIN
from lipjax.data.synthetic.primitives import _cache_hulls, _Ground
from lipjax.data.synthetic.scene import Light, Scene
from lipjax.data.synthetic.shadows import _shadows
from lipjax.data.synthetic.surfaces import _surfaces
from lipjax.data.synthetic.visibility import _CameraRays, _visibility


def _by_material(prims: list) -> list:
    """The primitives reordered so that those sharing a material are adjacent (stable), so that a material
    is evaluated once for all of them."""
    first: dict[int, int] = {}
    for i, p in enumerate(prims):
        first.setdefault(id(p.mat), i)
    return sorted(prims, key=lambda p: first[id(p.mat)])


@dataclasses.dataclass
class _Surfaces:
    """Per pixel (flat, N = H * W): what the camera ray hits and the surface there. Float32 unless noted."""

    hit: np.ndarray  # bool, a primitive is hit
    tz: np.ndarray  # z-depth of the hit, 0 where none
    d: tuple  # ray directions (dx, dy, dz), world
    p: tuple  # hit points (px, py, pz), world
    n: tuple  # normals (nx, ny, nz), world
    albedo: np.ndarray  # (3, N) linear
    emit: np.ndarray
    spec: np.ndarray
    shin: np.ndarray
    labels: np.ndarray  # int8, index into LABELS


def _surfaces_of(prims: list, scene: Scene, rays: _CameraRays, zbuf, ids, intr: Intrinsics) -> _Surfaces:
    """Normals, albedo, emission, gloss and labels of every pixel's hit."""
    ox, oy, oz = rays.origin
    dx, dy, dz = rays.d
    N = ids.size
    idf = ids.ravel()
    zf = zbuf.ravel()
    hit = idf >= 0
    tz = np.where(hit, zf, 0.0).astype(_F32)
    dxf, dyf, dzf = dx.ravel(), dy.ravel(), dz.ravel()
    px, py, pz = ox + tz * dxf, oy + tz * dyf, oz + tz * dzf
    # Sort the hit pixels by primitive once: every primitive then works on contiguous slices, and the
    # results are scattered back with one write per quantity.
    order = np.argsort(idf, kind="stable")
    counts = np.bincount(idf.astype(np.int64) + 1, minlength=len(prims) + 1)
    sel = order[counts[0]:]
    counts = counts[1:]  # pixels per primitive
    spx, spy, spz = px.take(sel), py.take(sel), pz.take(sel)  # (take: faster than fancy indexing)
    sfp = tz.take(sel) * (1.0 / min(intr.fx, intr.fy))  # pixel footprint in metres at that depth
    mat_out, normals, hit_labels = _surfaces(prims, counts, spx, spy, spz, sfp)
    alb = np.zeros((3, N), _F32)
    nx, ny, nz = np.zeros(N, _F32), np.zeros(N, _F32), np.zeros(N, _F32)
    emit = np.zeros(N, _F32)
    spec = np.zeros(N, _F32)
    shin = np.ones(N, _F32)
    labels = np.zeros(N, np.int8)
    if sel.size:
        _set_cols(alb, sel, mat_out[0])
        for arr, val in zip((nx, ny, nz, emit, spec, shin, labels), (*normals, *mat_out[1:], hit_labels)):
            arr[sel] = val
    if scene.terrain_x is not None:
        labels[(labels == _ROAD) & (np.abs(px) > scene.terrain_x)] = _TERRAIN
    return _Surfaces(hit, tz, (dxf, dyf, dzf), (px, py, pz), (nx, ny, nz), alb, emit, spec, shin, labels)


def _shadow_mask(scene: Scene, light: Light, recv, s: _Surfaces, intr: Intrinsics, H: int, W: int) -> np.ndarray:
    """(N,) float32 in [0, 1]: how much of `light` reaches each pixel's surface.

    Shadow rays for one pixel in each 2x2 block (the mask is then upsampled and softened): a quarter of the work,
    at the cost of shadow edges resolved to 2 pixels."""
    sub = (slice(0, None, 2), slice(0, None, 2))
    lit = _shadows(scene, light, *(np.ascontiguousarray(a.reshape(H, W)[sub]) for a in (recv, *s.p)),
                   *(np.ascontiguousarray(a.reshape(H, W)[sub]) for a in s.n),
                   Intrinsics(intr.fx / 2, intr.fy / 2, intr.cx / 2, intr.cy / 2), (H + 1) // 2, (W + 1) // 2)
    lit = np.repeat(np.repeat(lit, 2, axis=0), 2, axis=1)[:H, :W]
    if light.shadow_blur > 0:  # a box blur: penumbrae, and it hides the stair steps
        k = 2 * light.shadow_blur + 1
        lit = cv2.blur(lit, (k, k), borderType=cv2.BORDER_REPLICATE)
    return lit.ravel()


def _shade(scene: Scene, s: _Surfaces, intr: Intrinsics, H: int, W: int) -> np.ndarray:
    """(3, N) linear radiance of the hit surfaces: ambient, each light's Lambertian term (shadowed, with a point
    light's falloff) and gloss, emission, then distance haze."""
    nx, ny, nz = s.n
    px, py, pz = s.p
    E = scene.ambient * (1.0 + scene.ambient_up * ny)  # (3, N)
    glossy = np.flatnonzero(s.spec > 0)
    spec_rgb = np.zeros((3, glossy.size), _F32)
    if glossy.size:
        vx, vy, vz = (-a[glossy] for a in s.d)
        vn = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
        vx, vy, vz = vx * vn, vy * vn, vz * vn
    for light in scene.lights:
        if light.direction is not None:
            lx, ly, lz = (float(c) for c in light.direction)
            ndl = nx * lx + ny * ly + nz * lz
            fall = None
        else:
            lx, ly, lz = light.position[0] - px, light.position[1] - py, light.position[2] - pz
            d2 = lx * lx + ly * ly + lz * lz
            il = 1.0 / np.sqrt(d2)
            lx, ly, lz = lx * il, ly * il, lz * il
            ndl = nx * lx + ny * ly + nz * lz
            fall = 1.0 / (1.0 + d2 * (1.0 / (light.r0 * light.r0)))
        recv = s.hit & (ndl > 0) & (s.emit <= 0)
        w = np.maximum(ndl, 0.0) * _shadow_mask(scene, light, recv, s, intr, H, W)
        if fall is not None:
            w = w * fall
        E += light.color * w
        if glossy.size:
            if np.ndim(lx):
                gx, gy, gz = lx[glossy], ly[glossy], lz[glossy]
            else:
                gx, gy, gz = lx, ly, lz
            hx, hy, hz = gx + vx, gy + vy, gz + vz
            hn = 1.0 / np.sqrt(hx * hx + hy * hy + hz * hz + 1e-12)
            ndh = np.maximum((nx[glossy] * hx + ny[glossy] * hy + nz[glossy] * hz) * hn, 0.0)
            sh = s.shin[glossy]
            lobe = ndh / (sh - sh * ndh + ndh + 1e-6)  # Schlick's cheap stand-in for ndh ** shininess
            spec_rgb += light.color * (s.spec[glossy] * lobe * w[glossy])
    lin = s.albedo * (E + s.emit)
    if glossy.size:
        _set_cols(lin, glossy, _cols(lin, glossy) + spec_rgb)
    if scene.haze_dist > 0:  # aerial perspective (sky pixels are overwritten below)
        f = np.exp(s.tz * (-1.0 / scene.haze_dist))
        lin *= f
        lin += scene.haze_color * (1.0 - f)
    return lin


def _paint_sky(scene: Scene, lin: np.ndarray, sky_px: np.ndarray, intr: Intrinsics, H: int, W: int) -> None:
    """Writes the sky's radiance into the (3, N) `lin` where `sky_px`: the sky is smooth, so it is shaded at 1/4
    resolution and upsampled bilinearly."""
    r = [float(x) for x in scene.cam_R.ravel()]  # camera-to-world rotation, row-major
    hs, ws = -(-H // 4), -(-W // 4)
    xs = ((4.0 * np.arange(ws) + 1.5 - intr.cx) / intr.fx).astype(_F32)
    ys = ((4.0 * np.arange(hs) + 1.5 - intr.cy) / intr.fy).astype(_F32)
    sx = ((r[0] * xs)[None, :] + (r[1] * ys + r[2])[:, None]).ravel()
    sy = ((r[3] * xs)[None, :] + (r[4] * ys + r[5])[:, None]).ravel()
    sz = ((r[6] * xs)[None, :] + (r[7] * ys + r[8])[:, None]).ravel()
    inv = 1.0 / np.sqrt(sx * sx + sy * sy + sz * sz)
    small = scene.sky(sx * inv, sy * inv, sz * inv).reshape(3, hs, ws)
    for c in range(3):
        np.copyto(lin[c], cv2.resize(small[c], (W, H), interpolation=cv2.INTER_LINEAR).ravel(), where=sky_px)


@dataclasses.dataclass(frozen=True)
class Reflection:
    """A polished floor or a wet road: the scene mirrored in the plane y = 0 seen on it; the depth is untouched.

    On the floor and road pixels the radiance is L = (1 - F) L_surface + F L_mirror, with Schlick's Fresnel term
    F = strength + (1 - strength) (1 - cos theta)^5 (theta: the view ray's angle to the floor's normal), so the
    mirror image is faint looking down and strong at grazing angles. L_mirror is what the camera mirrored in
    y = 0 sees (the same scene, rendered at half size), blurred by a Gaussian of `blur_px` pixels (the gloss's
    roughness). Photographs of rooms and streets are full of such images (tiled and polished floors, wet
    asphalt): colour structure where the geometry is one plane.
    """

    strength: float  # reflectance at normal incidence, in (0, 1]
    blur_px: float = 1.0  # sigma of the roughness blur, full-size pixels; 0: a sharp mirror

    def __post_init__(self):
        if not 0 < self.strength <= 1 or not self.blur_px >= 0:
            raise ValueError(f"Reflection needs 0 < strength <= 1 and blur_px >= 0, got {self}")


_MIRROR_Y = np.diag([1.0, -1.0, 1.0])  # the reflection in the plane y = 0
_FLOOR_NORMAL_MIN_Y = 0.99  # a reflecting pixel's surface faces up (normal's y component at least this)
_FLOOR_HEIGHT_TOL_M = 1e-2  # and lies on y = 0 (rugs and mats, a few centimetres up, do not reflect)


def _lit(scene: Scene, prims: list, H: int, W: int, intr: Intrinsics) -> tuple[np.ndarray, _Surfaces, np.ndarray]:
    """(z-buffer (H, W), the surfaces hit, (3, H * W) linear radiance with the sky) of `prims` seen through the
    camera of `scene`."""
    rays = _CameraRays(scene, H, W, intr)
    zbuf, ids = _visibility(prims, scene, rays, intr)
    s = _surfaces_of(prims, scene, rays, zbuf, ids, intr)
    lin = _shade(scene, s, intr, H, W)
    if scene.sky is not None and (~s.hit).any():
        _paint_sky(scene, lin, ~s.hit, intr, H, W)
    return zbuf, s, lin


def _mirror_radiance(scene: Scene, prims: list, H: int, W: int, intr: Intrinsics, blur_px: float) -> np.ndarray:
    """(3, H * W) linear radiance that the camera mirrored in y = 0 sees, rendered at half size and upsampled.

    The mirrored camera's ray through a pixel is the reflection of the camera's ray: it crosses y = 0 where the
    camera's ray meets the floor and goes on into the scene as the reflected ray would. The ground plane is left
    out (the mirrored ray crosses it from below); a room's shell is an inside box, whose far side is what the ray
    leaves through."""
    mirrored = dataclasses.replace(scene, cam_pos=np.asarray(scene.cam_pos, np.float64) * (1.0, -1.0, 1.0),
                                   cam_R=_MIRROR_Y @ scene.cam_R)
    kept = [p for p in prims if not isinstance(p, _Ground)]
    h, w = (H + 1) // 2, (W + 1) // 2
    half = Intrinsics(intr.fx / 2, intr.fy / 2, intr.cx / 2, intr.cy / 2)  # pixel 2 i of the frame is pixel i
    _, _, lin = _lit(mirrored, kept, h, w, half)
    out = np.empty((3, H * W), _F32)
    for c in range(3):
        full = cv2.resize(lin[c].reshape(h, w), (W, H), interpolation=cv2.INTER_LINEAR)
        if blur_px > 0:
            full = cv2.GaussianBlur(full, (0, 0), blur_px, borderType=cv2.BORDER_REPLICATE)
        out[c] = full.ravel()
    return out


def _reflect(scene: Scene, prims: list, s: _Surfaces, lin: np.ndarray, reflection: Reflection, intr: Intrinsics,
             H: int, W: int) -> None:
    """Blends the mirror image into the (3, N) `lin` on the floor and road pixels (see `Reflection`)."""
    on_floor = (s.hit & np.isin(s.labels, (_FLOOR, _ROAD)) & (s.n[1] > _FLOOR_NORMAL_MIN_Y)
                & (np.abs(s.p[1]) < _FLOOR_HEIGHT_TOL_M))
    if not on_floor.any():
        return
    dx, dy, dz = (a[on_floor] for a in s.d)
    cos = np.clip(-dy / np.sqrt(dx * dx + dy * dy + dz * dz), 0.0, 1.0)
    f = reflection.strength + (1.0 - reflection.strength) * (1.0 - cos) ** 5
    mirror = _mirror_radiance(scene, prims, H, W, intr, reflection.blur_px)
    idx = np.flatnonzero(on_floor)
    _set_cols(lin, idx, (1.0 - f) * _cols(lin, idx) + f * _cols(mirror, idx))


def render_scene(scene: Scene, H: int, W: int, intr: Intrinsics, noise_rng,
                 reflection: Reflection | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Draws `scene` through the camera `intr` at H x W pixels; `noise_rng` (a numpy Generator) draws the sensor
    noise; `reflection`: a polished floor / wet road (`Reflection`), None: matte. Returns (rgb (H, W, 3) uint8,
    z-depth (H, W) float32 metres (0: nothing within scene.max_depth), labels (H, W) int8 (index into LABELS,
    0 = sky))."""
    prims = _by_material(scene.prims)
    _cache_hulls(prims)
    zbuf, s, lin = _lit(scene, prims, H, W, intr)
    if reflection is not None:
        _reflect(scene, prims, s, lin, reflection, intr, H, W)
    rgb = _camera_image(lin, scene, H, W, noise_rng)
    zf = zbuf.ravel()
    depth = np.where(s.hit & (zf <= scene.max_depth), zf, 0.0).astype(_F32).reshape(H, W)
    return rgb, depth, s.labels.reshape(H, W)
