"""Procedural, band-limited, tileable grey textures for the synthetic worlds.

Every texture is a square ``(S, S)`` float32 array with values in ``[0, 1]``
that tiles seamlessly (it wraps around both axes), generated from an explicit
:class:`numpy.random.Generator` (no hidden random state). A texture modulates
a material's per-channel albedo; it is sampled by the renderer through a mip
pyramid (:func:`mip_pyramid`) so that distant surfaces do not alias.

Texture row ``0`` is the *bottom* of a surface patch (``v = 0``) and column
``0`` its left edge (``u = 0``).
"""

from __future__ import annotations

import numpy as np

#: Side length of every texture in texels (a power of two, for the mip pyramid).
TEXTURE_SIZE = 256


def _spectral_noise(rng: np.random.Generator, size: int, *, beta: float, f_min: float, f_max: float,
                    aspect: float = 1.0) -> np.ndarray:
    """Tileable band-limited noise with a ``1/f**beta`` amplitude spectrum.

    Frequencies are in cycles per texture; ``aspect`` stretches the spectrum
    (values > 1 give streaks along rows, e.g. wood grain).
    """
    fy = np.fft.fftfreq(size)[:, None] * size
    fx = np.fft.rfftfreq(size)[None, :] * size
    f = np.sqrt((fx / aspect) ** 2 + (fy * aspect) ** 2)
    amp = np.zeros_like(f)
    band = (f >= f_min) & (f <= f_max)
    amp[band] = f[band] ** (-beta)
    phase = rng.uniform(0.0, 2.0 * np.pi, size=f.shape)
    spec = amp * np.exp(1j * phase)
    img = np.fft.irfft2(spec, s=(size, size))
    img -= img.mean()
    sd = img.std()
    return img / sd if sd > 0 else img


def _normalise(img: np.ndarray, lo: float, hi: float) -> np.ndarray:
    a, b = float(img.min()), float(img.max())
    if b - a < 1e-12:
        return np.full(img.shape, (lo + hi) / 2.0, np.float32)
    return (lo + (img - a) * (hi - lo) / (b - a)).astype(np.float32)


def _blur_wrap(img: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian blur with wrap-around borders (keeps textures tileable and band-limited)."""
    if sigma <= 0:
        return img
    n = img.shape[0]
    f = np.fft.fftfreq(n)
    g = np.exp(-2.0 * (np.pi * sigma) ** 2 * (f[:, None] ** 2 + f[None, :] ** 2))
    return np.real(np.fft.ifft2(np.fft.fft2(img) * g)).astype(np.float32)


def value_noise(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, octaves: int = 5, base_cells: int = 4,
                persistence: float = 0.55, lo: float = 0.25, hi: float = 0.85) -> np.ndarray:
    """Multi-octave tileable value noise (plaster, concrete, carpet, foliage).

    Each octave is a random lattice of ``base_cells * 2**k`` cells per side,
    interpolated with a periodic smooth-step; amplitudes fall by
    ``persistence`` per octave.

    Returns
    -------
    ndarray, shape (size, size), float32 in [lo, hi]
    """
    out = np.zeros((size, size), np.float64)
    amp = 1.0
    coords = np.arange(size) / size
    for k in range(octaves):
        n = base_cells * 2 ** k
        if n > size:
            break
        lattice = rng.random((n, n))
        x = coords * n
        i0 = np.floor(x).astype(int) % n
        i1 = (i0 + 1) % n
        f = x - np.floor(x)
        f = f * f * (3.0 - 2.0 * f)
        rows = lattice[i0][:, None, :] * (1 - f)[:, None, None] + lattice[i1][:, None, :] * f[:, None, None]
        rows = rows[:, 0, :]
        img = rows[:, i0] * (1 - f)[None, :] + rows[:, i1] * f[None, :]
        out += amp * img
        amp *= persistence
    return _normalise(out, lo, hi)


def plaster(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, lo: float = 0.55, hi: float = 0.8) -> np.ndarray:
    """Painted plaster: smooth low-contrast blotches plus fine grain."""
    a = _spectral_noise(rng, size, beta=1.6, f_min=1, f_max=size / 3)
    return _normalise(a, lo, hi)


def carpet(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, lo: float = 0.2, hi: float = 0.55) -> np.ndarray:
    """Carpet / linoleum: blotchy mid frequencies and speckle."""
    a = _spectral_noise(rng, size, beta=1.0, f_min=2, f_max=size / 2.5)
    return _normalise(a, lo, hi)


def wood(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, lo: float = 0.3, hi: float = 0.7,
         rings: float = 9.0) -> np.ndarray:
    """Wood grain: warped stripes along the texture's u axis (rows)."""
    warp = _spectral_noise(rng, size, beta=2.0, f_min=1, f_max=12, aspect=4.0)
    y = np.arange(size)[:, None] / size
    x = np.arange(size)[None, :] / size
    stripes = np.sin(2 * np.pi * (rings * y + 0.35 * warp + 0.05 * np.sin(2 * np.pi * x)))
    fine = _spectral_noise(rng, size, beta=0.8, f_min=8, f_max=size / 3, aspect=6.0)
    return _normalise(stripes + 0.35 * fine, lo, hi)


def tiles(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, n: int = 4, grout: float = 0.04,
          lo: float = 0.3, hi: float = 0.8, grout_level: float = 0.15) -> np.ndarray:
    """Square tiles (``n x n`` per texture) with jittered grey levels and dark grout."""
    tile_level = rng.uniform(0.35, 0.65, size=(n, n))
    idx = (np.arange(size) * n) // size
    img = tile_level[idx][:, idx]
    img = img + 0.08 * _spectral_noise(rng, size, beta=1.2, f_min=2, f_max=size / 3)
    frac = (np.arange(size) * n / size) % 1.0
    g = (frac < grout)
    mask = g[:, None] | g[None, :]
    img = np.where(mask, grout_level, img)
    return _normalise(_blur_wrap(img, 0.7), lo, hi)


def bricks(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, rows: int = 8, per_row: int = 4,
           lo: float = 0.2, hi: float = 0.75) -> np.ndarray:
    """Running-bond bricks with mortar lines."""
    img = np.empty((size, size), np.float64)
    rh = size // rows
    bw = size // per_row
    levels = rng.uniform(0.35, 0.7, size=(rows, per_row))
    for r in range(rows):
        off = (bw // 2) * (r % 2)
        cols = ((np.arange(size) + off) // bw) % per_row
        img[r * rh:(r + 1) * rh, :] = levels[r][cols]
        img[r * rh:r * rh + 2, :] = 0.85
        edge = ((np.arange(size) + off) % bw) < 2
        img[r * rh:(r + 1) * rh, edge] = 0.85
    img += 0.06 * _spectral_noise(rng, size, beta=1.0, f_min=4, f_max=size / 3)
    return _normalise(_blur_wrap(img, 0.6), lo, hi)


def ceiling_tiles(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, n: int = 4) -> np.ndarray:
    """Suspended-ceiling tiles: bright panels with perforation speckle and a dark grid."""
    img = 0.85 + 0.05 * _spectral_noise(rng, size, beta=0.5, f_min=20, f_max=size / 2.2)
    frac = (np.arange(size) * n / size) % 1.0
    g = frac < 0.03
    img = np.where(g[:, None] | g[None, :], 0.35, img)
    return _normalise(_blur_wrap(img, 0.6), 0.3, 0.9)


def bookshelf(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, shelves: int = 4) -> np.ndarray:
    """A shelf front: ``shelves`` boards with rows of book spines of random width and grey."""
    img = np.full((size, size), 0.12)
    sh = size // shelves
    for s in range(shelves):
        y0 = s * sh + 4
        x = 0
        while x < size:
            w = int(rng.integers(4, 14))
            h = int(rng.integers(int(sh * 0.55), sh - 6))
            img[y0:y0 + h, x:min(size, x + w - 1)] = rng.uniform(0.2, 0.95)
            if rng.random() < 0.5:  # a label band on the spine
                yl = y0 + int(h * rng.uniform(0.5, 0.8))
                img[yl:yl + 3, x:min(size, x + w - 1)] = rng.uniform(0.0, 1.0)
            x += w
        img[s * sh:s * sh + 4, :] = 0.55  # the shelf board
    return _normalise(_blur_wrap(img, 0.6), 0.05, 0.95)


def poster(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, n_shapes: int = 14) -> np.ndarray:
    """A poster or picture: a frame around random rectangles, discs and stripes."""
    y = np.arange(size)[:, None] / size
    x = np.arange(size)[None, :] / size
    img = np.full((size, size), rng.uniform(0.5, 0.95))
    img = img + 0.1 * _spectral_noise(rng, size, beta=1.5, f_min=1, f_max=6)
    for _ in range(n_shapes):
        kind = rng.integers(0, 4)
        v = rng.uniform(0.0, 1.0)
        cx, cy = rng.uniform(0.1, 0.9, size=2)
        if kind == 0:
            w, h = rng.uniform(0.05, 0.35, size=2)
            m = (np.abs(x - cx) < w / 2) & (np.abs(y - cy) < h / 2)
        elif kind == 1:
            r = rng.uniform(0.03, 0.18)
            m = (x - cx) ** 2 + (y - cy) ** 2 < r * r
        elif kind == 2:
            a, b = rng.uniform(0.03, 0.2, size=2)
            m = ((x - cx) / a) ** 2 + ((y - cy) / b) ** 2 < 1
        else:  # a text-like row of small blocks
            m = (np.abs(y - cy) < 0.015) & (np.abs(x - cx) < 0.25) & (((x * 40).astype(int) % 3) != 0)
        img = np.where(m, v, img)
    frame = 0.04
    border = (x < frame) | (x > 1 - frame) | (y < frame) | (y > 1 - frame)
    img = np.where(border, rng.uniform(0.05, 0.3), img)
    return _normalise(_blur_wrap(img, 0.8), 0.03, 0.97)


def curtain(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, folds: int = 6, lo: float = 0.25,
            hi: float = 0.7) -> np.ndarray:
    """Curtain fabric: vertical folds (shading varies along u) with a woven pattern."""
    x = np.arange(size)[None, :] / size
    phase = rng.uniform(0, 2 * np.pi, size=3)
    folds_img = (np.sin(2 * np.pi * folds * x + phase[0]) + 0.4 * np.sin(2 * np.pi * 2 * folds * x + phase[1]))
    pattern = _spectral_noise(rng, size, beta=1.2, f_min=3, f_max=size / 4)
    img = np.repeat(folds_img, size, axis=0) + 0.35 * pattern
    return _normalise(img, lo, hi)


def facade(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, floors: int = 4, windows: int = 4) -> np.ndarray:
    """A building facade: concrete with a ``floors x windows`` grid of dark windows with frames."""
    img = 0.6 + 0.08 * _spectral_noise(rng, size, beta=1.4, f_min=1, f_max=size / 4)
    fh = size // floors
    ww = size // windows
    for f in range(floors):
        for w in range(windows):
            y0 = f * fh + int(fh * 0.3)
            y1 = f * fh + int(fh * 0.85)
            x0 = w * ww + int(ww * 0.15)
            x1 = w * ww + int(ww * 0.85)
            glass = rng.uniform(0.05, 0.35)
            img[y0:y1, x0:x1] = glass + 0.1 * (np.arange(y1 - y0)[:, None] / (y1 - y0))
            img[y0:y1, (x0 + x1) // 2 - 1:(x0 + x1) // 2 + 1] = 0.8  # mullion
            img[y0 - 2:y0, x0 - 2:x1 + 2] = 0.85  # sill
    return _normalise(_blur_wrap(img, 0.6), 0.05, 0.9)


def foliage(rng: np.random.Generator, *, size: int = TEXTURE_SIZE) -> np.ndarray:
    """Leaves: clumped high-contrast noise."""
    a = _spectral_noise(rng, size, beta=0.9, f_min=6, f_max=size / 2.5)
    b = _spectral_noise(rng, size, beta=2.0, f_min=1, f_max=8)
    return _normalise(np.tanh(1.5 * a) + 0.6 * b, 0.1, 0.9)


def bark(rng: np.random.Generator, *, size: int = TEXTURE_SIZE) -> np.ndarray:
    """Bark: vertical furrows (along the texture's v axis)."""
    a = _spectral_noise(rng, size, beta=1.3, f_min=2, f_max=size / 3, aspect=0.25)
    return _normalise(a, 0.15, 0.7)


def panel(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, nx: int = 2, ny: int = 3, lo: float = 0.25,
          hi: float = 0.75) -> np.ndarray:
    """Cabinet / door front: ``nx x ny`` recessed panels with handles over a wood base."""
    img = wood(rng, size=size, lo=0.35, hi=0.6, rings=5.0).astype(np.float64)
    cw, ch = size // nx, size // ny
    for i in range(nx):
        for j in range(ny):
            x0, x1 = i * cw + 8, (i + 1) * cw - 8
            y0, y1 = j * ch + 8, (j + 1) * ch - 8
            img[y0:y0 + 3, x0:x1] = 0.15
            img[y1 - 3:y1, x0:x1] = 0.85
            img[y0:y1, x0:x0 + 3] = 0.2
            img[y0:y1, x1 - 3:x1] = 0.8
            hx = x1 - 14 if i % 2 == 0 else x0 + 10
            hy = (y0 + y1) // 2
            img[hy - 10:hy + 10, hx:hx + 4] = 0.95
    return _normalise(_blur_wrap(img, 0.6), lo, hi)


def window_view(rng: np.random.Generator, *, size: int = TEXTURE_SIZE) -> np.ndarray:
    """What one sees through a window: bright sky over a darker band of trees and houses, with mullions."""
    y = np.arange(size)[:, None] / size
    x = np.arange(size)[None, :] / size
    skyline = 0.35 + 0.12 * _spectral_noise(rng, size, beta=1.8, f_min=1, f_max=20)[0][None, :]
    img = np.where(y > skyline, 0.9 + 0.05 * y, 0.35 + 0.15 * foliage(rng, size=size))
    mull = (np.abs(x - 0.5) < 0.02) | (x < 0.03) | (x > 0.97) | (y < 0.03) | (y > 0.97) | (np.abs(y - 0.62) < 0.015)
    img = np.where(mull, 0.2, img)
    return _normalise(_blur_wrap(img, 0.7), 0.05, 1.0)


def stripes(rng: np.random.Generator, *, size: int = TEXTURE_SIZE, n: int = 8, lo: float = 0.2,
            hi: float = 0.8) -> np.ndarray:
    """Horizontal stripes of random grey (blinds, radiators, railings)."""
    lev = rng.uniform(0.0, 1.0, size=n)
    rows = lev[(np.arange(size) * n) // size]
    img = np.repeat(rows[:, None], size, axis=1)
    return _normalise(_blur_wrap(img, 1.0), lo, hi)


def uniform(level: float = 1.0, *, size: int = TEXTURE_SIZE) -> np.ndarray:
    """A constant texture (plain paint, emitters, screens)."""
    return np.full((size, size), float(level), np.float32)


def mip_pyramid(texture: np.ndarray) -> list[np.ndarray]:
    """Box-filtered mip pyramid of a square power-of-two texture, largest level first.

    Parameters
    ----------
    texture : ndarray, shape (S, S)

    Returns
    -------
    list of ndarray
        Levels of shapes ``(S, S), (S/2, S/2), ..., (1, 1)``.
    """
    t = np.asarray(texture, np.float32)
    s = t.shape[0]
    if t.shape != (s, s) or s & (s - 1):
        raise ValueError(f"texture must be square with a power-of-two side, got {t.shape}")
    levels = [t]
    while t.shape[0] > 1:
        t = 0.25 * (t[0::2, 0::2] + t[1::2, 0::2] + t[0::2, 1::2] + t[1::2, 1::2])
        levels.append(t.astype(np.float32))
    return levels
