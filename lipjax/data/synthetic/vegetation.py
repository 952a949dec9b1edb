"""Trees (a trunk and a crown of blobs; the trees of a street share one or two species), the rows of trees along a
street and the bushes beside it. Units: metres."""
from __future__ import annotations

import dataclasses

from lipjax.data.synthetic.colour import _hsv
from lipjax.data.synthetic.constants import _VEGETATION
from lipjax.data.synthetic.materials import _Mat
from lipjax.data.synthetic.patterns import _p_foliage, _p_noise
from lipjax.data.synthetic.scene import _Builder
from lipjax.data.synthetic.street import Street


@dataclasses.dataclass(frozen=True)
class TreeRowRanges:
    """Rows of trees along the street: each side is skipped with probability `skip_p` (urban / other), the first
    tree's distance, the spacing (non-open / open streets; each gap jittered by `jitter`), the distance beyond the
    curb (as a fraction of the sidewalk, or in metres without one), and how far the rows reach (metres)."""

    skip_p: tuple[float, float] = (0.5, 0.25)
    first_m: tuple[float, float] = (0, 15)
    spacing_m: tuple[float, float] = (10, 22)
    open_spacing_m: tuple[float, float] = (6, 14)
    jitter: tuple[float, float] = (0.7, 1.3)
    on_sidewalk: tuple[float, float] = (0.5, 0.8)
    off_road_m: tuple[float, float] = (1.5, 6.0)
    until_m: float = 75.0


TREE_ROWS = TreeRowRanges()


def species(rng) -> tuple:
    """A tree species: bark and foliage materials, trunk height and crown size ranges (shared by the trees
    of a street, as on real streets)."""
    bark = _Mat(_p_noise(rng, c := _hsv(rng.uniform(0.05, 0.12), rng.uniform(0.15, 0.5), rng.uniform(0.12, 0.4)),
                         c * 0.6, 6.0, 1, 1.2, stretch=0.2))
    return bark, _Mat(_p_foliage(rng)), rng.uniform(1.5, 3.5), rng.uniform(1.0, 2.6)


def tree(b: _Builder, rng, x, z, species, scale=1.0):
    """A tree of `species` standing at (x, z), scaled by `scale`; one shadow caster."""
    with b.assembly():
        _tree_parts(b, rng, x, z, species, scale)


def _tree_parts(b: _Builder, rng, x, z, species, scale):
    bark, leaves, trunk, crown = species
    th = trunk * rng.uniform(0.8, 1.2) * scale
    tr = rng.uniform(0.08, 0.2) * scale * crown / 1.8
    b.cyl((x, th / 2, z), tr, th / 2, _VEGETATION, bark)
    cr = crown * rng.uniform(0.8, 1.2) * scale
    n = int(rng.integers(3, 7)) if z < 40 else int(rng.integers(2, 4))  # fewer, bigger blobs far away
    k = 0.7 if z < 40 else 0.85
    cs = [(x + rng.normal(0, cr * 0.45), th + cr * rng.uniform(0.4, 1.4), z + rng.normal(0, cr * 0.45))
          for _ in range(n)]
    b.spheres(cs, rng.uniform(0.5, 1.0, n) * cr * k, _VEGETATION, leaves)


def tree_rows(b: _Builder, rng, street: Street, kinds: list, r: TreeRowRanges = TREE_ROWS) -> None:
    """A row of trees of one of the street's species along each side (on the sidewalk, or off the road)."""
    half, sw = street.half_width, street.sidewalk
    for s in (-1, 1):
        if rng.random() < (r.skip_p[0] if street.style == "urban" else r.skip_p[1]):
            continue
        z = rng.uniform(*r.first_m)
        spacing = rng.uniform(*r.spacing_m) if street.style != "open" else rng.uniform(*r.open_spacing_m)
        xt = s * (half + (sw * rng.uniform(*r.on_sidewalk) if sw > 0 else rng.uniform(*r.off_road_m)))
        sp = kinds[int(rng.integers(0, len(kinds)))]
        while z < min(street.length, r.until_m):
            tree(b, rng, xt + rng.normal(0, 0.3 if sw > 0 else 2.0), z, sp, rng.uniform(0.7, 1.3))
            z += spacing * rng.uniform(*r.jitter)


def bushes(b: _Builder, rng, street: Street) -> None:
    """Clumps of foliage blobs on the ground beside the street (fewer on urban streets)."""
    for _ in range(int(rng.integers(0, 6)) if street.style != "urban" else int(rng.integers(0, 3))):
        s = rng.choice([-1.0, 1.0])
        xb, zb = s * (street.edge + rng.uniform(0.3, 6.0)), rng.uniform(4, 60)
        n = int(rng.integers(2, 6))
        cs = [(xb + rng.normal(0, 0.6), rng.uniform(0.0, 0.5), zb + rng.normal(0, 1.0)) for _ in range(n)]
        b.spheres(cs, rng.uniform(0.4, 1.0, n), _VEGETATION, _Mat(_p_foliage(rng)))
