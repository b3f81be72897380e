"""Rendering: the image, chunk by chunk of pixels (over worker processes when
asked), each pixel the plain mean of its camera samples' radiance (a box
filter, integrator/src/render.rs `PixelRenderer::pixel`).

Random numbers: numpy's PCG64, one stream per chunk of pixels, seeded by
SeedSequence([seed, chunk]), so the image does not depend on the processes.
"""

from __future__ import annotations

import numpy as np

from camera import camera_frame, camera_rays, pixel_samples
from intersect import Intersector
from sampling import Options, pattern_points
from scene_file import Scene
from shading import Shader


class Renderer:
    def __init__(self, scene: Scene, opts: Options):
        self.scene, self.o = scene, opts
        self.cam = camera_frame(scene, opts)
        eps = 1e-7 * scene.scale  # our shadow-ray offset (Glint's is an error bound)
        self.hits = Intersector(scene, opts.mistakes, eps)
        self.shader = Shader(scene, opts, self.hits)

    def render_chunk(self, pix0: int, pix1: int, rng: np.random.Generator, shared=None):
        """The pixels pix0 .. pix1 - 1 (row-major), as (pix1 - pix0, 3)."""
        o, scene = self.o, self.scene
        P = pix1 - pix0
        rx, ry = pixel_samples(o, pix0, pix1, rng, None if shared is None else shared[0])
        M = rx.shape[0]
        d = camera_rays(self.cam, o, rx, ry)
        pos = scene.camera.position
        t, kind, index = self.hits.closest(pos, d)
        shared_light = None
        if shared is not None:  # MISTAKE (shared-samples): the same light points in every pixel
            shared_light = np.broadcast_to(shared[1], (P, o.spp, o.light_samples, 2)).reshape(M, o.light_samples, 2)
        radiance = self.shader.radiance(pos, d, t, kind, index, rng, shared_light)
        return radiance.reshape(P, o.spp, 3).mean(axis=1)


def _render_range(args):
    renderer, chunks, base_seed, shared = args
    out = []
    for ci, (p0, p1) in chunks:
        rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([base_seed, ci])))
        out.append((p0, p1, renderer.render_chunk(p0, p1, rng, shared)))
    return out


def render(scene: Scene, opts: Options, jobs: int = 1) -> np.ndarray:
    r = Renderer(scene, opts)
    npix = opts.width * opts.height
    per_pixel = opts.spp * max(1, opts.light_samples)
    pixels_per_chunk = max(1, min(4096, (1 << 18) // per_pixel))
    chunks = list(enumerate((p, min(npix, p + pixels_per_chunk)) for p in range(0, npix, pixels_per_chunk)))
    shared = None
    if "shared-samples" in opts.mistakes:
        # MISTAKE: one pixel pattern and one set of light points, reused everywhere.
        g = np.random.Generator(np.random.PCG64(np.random.SeedSequence([opts.seed, 1 << 40])))
        shared = (pattern_points(opts.sampler, (), opts.spp, g),
                  pattern_points(opts.light_sampler, (opts.spp,), opts.light_samples, g))
    film = np.zeros((npix, 3))
    if jobs <= 1 or len(chunks) == 1:
        results = [_render_range((r, chunks, opts.seed, shared))]
    else:
        import multiprocessing as mp

        groups = [chunks[i::jobs] for i in range(jobs)]
        with mp.get_context("fork").Pool(jobs) as pool:
            results = pool.map(_render_range, [(r, g, opts.seed, shared) for g in groups])
    for result in results:
        for p0, p1, values in result:
            film[p0:p1] = values
    film = film.reshape(opts.height, opts.width, 3)
    if "flipped-image" in opts.mistakes:  # MISTAKE: rows upside down
        film = film[::-1]
    return film


def keep_freed_memory():
    """Each chunk allocates and frees temporaries of a few MB; by default glibc
    returns them to the kernel (mmap / trim) and page-faults them back in,
    which costs as much system time as the arithmetic. Keep them instead
    (glibc only; elsewhere nothing changes but the speed)."""
    try:
        import ctypes

        libc = ctypes.CDLL(None)
        libc.mallopt(-3, 32 << 20)  # M_MMAP_THRESHOLD: blocks up to 32 MB from the heap
        libc.mallopt(-1, 1 << 30)  # M_TRIM_THRESHOLD: keep up to 1 GB of freed heap
    except (OSError, AttributeError):
        pass

