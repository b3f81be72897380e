"""The camera: where a pixel's samples lie on the film, and the ray from the
camera through each (camera/src/camera.rs).
"""

from __future__ import annotations

import math

import numpy as np

from sampling import Options, pattern_points
from scene_file import InputError, Scene


def camera_frame(scene: Scene, opts: Options):
    """(position, f forward, hw right, hh up): the camera's position and the
    film's axes, scaled to its half width and half height (camera/src/camera.rs
    `Camera::new`): forward = normalize(look_at - position), right =
    normalize(forward x normalize(up)), up' = right x forward."""
    m = opts.mistakes
    cam = scene.camera
    forward = cam.look_at - cam.position
    if not np.linalg.norm(forward) > 0:
        raise InputError(f"{scene.path}: camera.look_at: the camera position and the look-at point coincide")
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, cam.up / np.linalg.norm(cam.up))
    if np.linalg.norm(right) <= 1e-3:
        raise InputError(f"{scene.path}: camera.up: parallel to the viewing direction")
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    aspect = opts.width / opts.height
    # camera/src/camera.rs: half height f*tan(fov/2) (fov vertical), half width aspect*that.
    half_angle = math.radians(cam.fov) / 2
    if "fov-no-half" in m:  # MISTAKE: tan(fov) instead of tan(fov/2)
        half_angle = math.radians(cam.fov)
        if half_angle >= math.pi / 2:
            raise InputError("fov-no-half needs fov < 90 degrees")
    half_height = cam.focal_length * math.tan(half_angle)
    half_width = aspect * half_height
    if "horizontal-fov" in m:  # MISTAKE: the fov spans the width, not the height
        half_width = cam.focal_length * math.tan(half_angle)
        half_height = half_width / aspect
    return (cam.position, forward * cam.focal_length, right * half_width, up * half_height)


def pixel_samples(opts: Options, pix0: int, pix1: int, rng: np.random.Generator, shared_jitter=None):
    """Raster positions (rx, ry) of the `spp` camera samples of each of the
    pixels pix0 .. pix1 - 1 (row-major), pixel by pixel: pixel (X, Y) covers
    [X, X+1) x [Y, Y+1), its samples in the pattern `opts.sampler`."""
    W = opts.width
    P = pix1 - pix0
    pix = np.arange(pix0, pix1)
    px, py = (pix % W).astype(np.float64), (pix // W).astype(np.float64)
    if shared_jitter is not None:  # MISTAKE (shared-samples): the same jitter in every pixel
        jitter = np.broadcast_to(shared_jitter, (P, opts.spp, 2))
    else:
        jitter = pattern_points(opts.sampler, (P,), opts.spp, rng)
    rx = (px[:, None] + jitter[..., 0]).ravel()
    ry = (py[:, None] + jitter[..., 1]).ravel()
    if "pixel-corners" in opts.mistakes:  # MISTAKE: every sample half a pixel up and left
        rx, ry = rx - 0.5, ry - 0.5
    return rx, ry


def camera_rays(frame, opts: Options, rx, ry):
    """Unit directions of the rays through raster (rx, ry), (0, 0) the top-left
    corner, pixel centres at +0.5 (camera/src/camera.rs `film_point`): NDC
    x = 2 rx / W - 1, y = 1 - 2 ry / H; direction = normalize(f forward +
    x hw right + y hh up), as [x, y, z] arrays. `frame` is camera_frame's."""
    pos, fwd, right, up = frame
    nx = 2.0 * rx / opts.width - 1.0
    ny = 1.0 - 2.0 * ry / opts.height
    d = [fwd[i] + nx * right[i] + ny * up[i] for i in range(3)]
    inv = 1.0 / np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
    return [d[i] * inv for i in range(3)]
