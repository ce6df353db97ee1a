"""How far a frame is from the exact one, as users see it, in numpy only (the tests and the
view benchmark share it). Frames are cell-id images (0: background, else 1 + the cell's
natural index, `resmr_testing.cell_ids`) of the same camera and size: `got` drawn at some
tolerance, `exact` at 0 px."""
import numpy as np


def _shifted(image, dy, dx, fill):
    """`image` moved by (dy, dx) pixels, `fill` where nothing moved in."""
    out = np.full_like(image, fill)
    height, width = image.shape
    out[max(dy, 0):height + min(dy, 0), max(dx, 0):width + min(dx, 0)] = \
        image[max(-dy, 0):height + min(-dy, 0), max(-dx, 0):width + min(-dx, 0)]
    return out


def cell_agreement(got, exact):
    """Share of the pixels both cover that name the same cell."""
    both = (got > 0) & (exact > 0)
    return float(np.mean(got[both] == exact[both])) if both.any() else 0.0


def missed_pixels(got, exact, reach=2, scale=1):
    """The pixels either covers whose content (a cell, or the background) the other image has
    nowhere within `reach` pixels (a square): a cell drawn up to `reach` pixels from where
    the exact image has it is not missed, a cell or a hole the exact image has nowhere near
    is. `exact` may be drawn at `scale` (odd) times the resolution, so that cells thinner than
    a pixel all appear in it: then a pixel of `got` is not missed when its content is in
    `exact` within `reach` pixels of the pixel's footprint, and the exact side when one of the
    `scale` x `scale` samples under the pixel has its content in `got` within `reach`. At 1x a
    cell thinner than a pixel shows only where a pixel's centre falls in it, so a frame naming
    a neighbouring sub-pixel cell counts as missed (the exact frame sampled a third of a pixel
    aside scores so too); the 1x frame is the 3x frame's centre samples."""
    height, width = got.shape
    assert exact.shape == (height * scale, width * scale) and scale % 2 == 1
    found_got = np.zeros(got.shape, bool)    # got's pixel has its match in exact nearby
    found_exact = np.zeros(got.shape, bool)  # one exact sample under the pixel has its match in got nearby
    for u in range(scale):
        for v in range(scale):
            sample = np.ascontiguousarray(exact[u::scale, v::scale])
            sample_found = np.zeros(got.shape, bool)
            for dy in range(-reach, reach + 1):
                for dx in range(-reach, reach + 1):
                    found_got |= _shifted(sample, dy, dx, -1) == got
                    sample_found |= _shifted(got, dy, dx, -1) == sample
            found_exact |= sample_found
    exact_covered = (exact.reshape(height, scale, width, scale) > 0).any(axis=(1, 3))
    return ((got > 0) | exact_covered) & ~(found_got & found_exact)


def within_pixels(got, exact, reach=2, scale=1):
    """Share of the pixels either covers that missed_pixels does not count."""
    height, width = got.shape
    covered = (got > 0) | (exact.reshape(height, scale, width, scale) > 0).any(axis=(1, 3))
    if not covered.any():
        return 1.0
    return 1.0 - float(missed_pixels(got, exact, reach, scale).sum()) / float(covered.sum())


def _dilate(mask):
    out = mask.copy()
    out[1:, :] |= mask[:-1, :]
    out[:-1, :] |= mask[1:, :]
    out[:, 1:] |= mask[:, :-1]
    out[:, :-1] |= mask[:, 1:]
    return out


def _within(mask, reach):
    """Pixels within `reach` pixels (a square) of `mask`."""
    out = mask.copy()
    for dy in range(-reach, reach + 1):
        for dx in range(-reach, reach + 1):
            out |= _shifted(mask, dy, dx, False)
    return out


def hole_mask(got, exact, reach=1):
    """Background pixels of `got` that no background of the exact image reaches through
    `got`'s background: gaps in the surface one sees through, not a silhouette drawn a little
    inside the exact one. The reach steps 4-connected (`reach` 1), or up to `reach` pixels (a
    square): a background wedge thinner than a pixel, where the coarse outline of a real gap
    strays past the exact one, samples as pixels that far apart."""
    open_ = got == 0
    reached = open_ & (exact == 0)
    while True:
        grown = (_dilate(reached) if reach == 1 else _within(reached, reach)) & open_
        if np.array_equal(grown, reached):
            break
        reached = grown
    return open_ & ~reached


def see_through_holes(got, exact, reach=1):
    """The pixels of hole_mask (see-through gaps) and the deepest: the largest distance in
    pixels from a hole pixel to the hole's edge."""
    holes = hole_mask(got, exact, reach)
    count = int(holes.sum())
    depth = 0
    remaining = holes
    while remaining.any():
        depth += 1
        shrunk = remaining.copy()
        shrunk[1:, :] &= remaining[:-1, :]
        shrunk[:-1, :] &= remaining[1:, :]
        shrunk[:, 1:] &= remaining[:, :-1]
        shrunk[:, :-1] &= remaining[:, 1:]
        remaining = shrunk
    return count, depth


def silhouette_distance(got, exact, limit=256):
    """The largest distance, pixels (a square reach, at most `limit`), from a pixel covered in
    one image and not the other to the nearest pixel covered in the other: how far the
    outline strays."""
    a, b = got > 0, exact > 0
    worst = 0
    for source, target in ((a & ~b, b), (b & ~a, a)):
        if not source.any():
            continue
        if not target.any():
            return limit
        grown, steps = target.copy(), 0
        while (source & ~grown).any() and steps < limit:
            steps += 1
            grown = _within(grown, 1)
        worst = max(worst, steps)
    return worst


def nan_pixels(rgb, nan_color):
    """Pixels of an RGB frame (0-255) painted exactly in the lookup table's NaN colour."""
    target = np.round(np.asarray(nan_color) * 255).astype(np.int64)
    return int(np.sum(np.all(rgb == target, axis=-1)))


def compare(got, exact, hole_reach=1):
    """All of the above for one frame: a dict (holes as see_through_holes with `hole_reach`)."""
    holes, deepest = see_through_holes(got, exact, hole_reach)
    return {"cell_agreement": cell_agreement(got, exact), "within_2px": within_pixels(got, exact, 2),
            "hole_pixels": holes, "hole_depth_px": deepest,
            "silhouette_px": silhouette_distance(got, exact)}
