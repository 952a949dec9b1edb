"""The frame renderer: visibility, surfaces, lighting (shadows, gloss, haze, sky), then the camera model."""
from __future__ import annotations

import cv2
import numpy as np

from lipjax.data.sample import Intrinsics
from lipjax.data.synthetic.arrays import _cols, _set_cols
from lipjax.data.synthetic.camera import _camera_image
from lipjax.data.synthetic.constants import _F32, _ROAD, _TERRAIN
from lipjax.data.synthetic.primitives import _cache_hulls
from lipjax.data.synthetic.scene import Scene
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


def render_scene(scene: Scene, H: int, W: int, intr: Intrinsics, noise_rng) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    prims = _by_material(scene.prims)
    _cache_hulls(prims)
    rays = _CameraRays(scene, H, W, intr)
    ox, oy, oz = rays.origin
    dx, dy, dz = rays.d
    r = [float(x) for x in scene.cam_R.ravel()]  # camera-to-world rotation, row-major (sky rays below)
    zbuf, ids = _visibility(prims, scene, rays, intr)

    # ---- surfaces: normals, albedo, emission, gloss per pixel
    N = H * W
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
    terrain_x = getattr(scene, "terrain_x", None)
    if terrain_x is not None:
        labels[(labels == _ROAD) & (np.abs(px) > terrain_x)] = _TERRAIN

    # ---- lighting
    E = scene.ambient * (1.0 + scene.ambient_up * ny)  # (3, N)
    glossy = np.flatnonzero(spec > 0)
    spec_rgb = np.zeros((3, glossy.size), _F32)
    if glossy.size:
        vx, vy, vz = -dxf[glossy], -dyf[glossy], -dzf[glossy]
        vn = 1.0 / np.sqrt(vx * vx + vy * vy + vz * vz)
        vx, vy, vz = vx * vn, vy * vn, vz * vn
    nx2, ny2, nz2 = nx.reshape(H, W), ny.reshape(H, W), nz.reshape(H, W)
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
        recv = hit & (ndl > 0) & (emit <= 0)
        # Shadow rays for one pixel in each 2x2 block (the mask is then upsampled and softened): a quarter of
        # the work, at the cost of shadow edges resolved to 2 pixels.
        sub = (slice(0, None, 2), slice(0, None, 2))
        lit = _shadows(scene, light, *(np.ascontiguousarray(a.reshape(H, W)[sub]) for a in (recv, px, py, pz)),
                       *(np.ascontiguousarray(a[sub]) for a in (nx2, ny2, nz2)),
                       Intrinsics(intr.fx / 2, intr.fy / 2, intr.cx / 2, intr.cy / 2), (H + 1) // 2, (W + 1) // 2)
        lit = np.repeat(np.repeat(lit, 2, axis=0), 2, axis=1)[:H, :W]
        if light.shadow_blur > 0:  # a box blur: penumbrae, and it hides the stair steps
            k = 2 * light.shadow_blur + 1
            lit = cv2.blur(lit, (k, k), borderType=cv2.BORDER_REPLICATE)
        shade = lit.ravel()
        w = np.maximum(ndl, 0.0) * shade
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
            sh = shin[glossy]
            lobe = ndh / (sh - sh * ndh + ndh + 1e-6)  # Schlick's cheap stand-in for ndh ** shininess
            spec_rgb += light.color * (spec[glossy] * lobe * w[glossy])
    lin = alb * (E + emit)
    if glossy.size:
        _set_cols(lin, glossy, _cols(lin, glossy) + spec_rgb)
    if scene.haze_dist > 0:  # aerial perspective (sky pixels are overwritten below)
        f = np.exp(tz * (-1.0 / scene.haze_dist))
        lin *= f
        lin += scene.haze_color * (1.0 - f)
    if scene.sky is not None:
        sky_px = ~hit
        if sky_px.any():  # the sky is smooth: shade it at 1/4 resolution, upsample bilinearly
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

    rgb = _camera_image(lin, scene, H, W, noise_rng)

    depth = np.where(hit & (zf <= scene.max_depth), zf, 0.0).astype(_F32).reshape(H, W)
    return rgb, depth, labels.reshape(H, W)
