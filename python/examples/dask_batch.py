"""A batch over many volumes on Dask's distributed scheduler.

    pip install "dask[distributed]"
    python python/examples/dask_batch.py [--volumes gaussians@48:1 gaussians@48:2 ...]
                                         [--views 64] [--chunk 16] [--workers 2]

Each task renders one chunk of views of one volume. The renderer is built
once per volume per worker process (a process-wide cache, `renderer_for`),
so a worker that gets several chunks of a volume prepares its spectrum
once; each chunk then runs on all the worker's threads with the GIL
released. The result is one (volumes, views, H, W) array.
"""

import argparse
import functools

import numpy as np

import fvr


@functools.lru_cache(maxsize=4)
def renderer_for(spec):
    """One Renderer per volume in this worker process (at most 4 kept)."""
    return fvr.Renderer(spec)


def render_chunk(spec, rotations, size):
    return renderer_for(spec).project(rotations, size=size)


def random_rotations(count, seed=0):
    rng = np.random.default_rng(seed)
    q, r = np.linalg.qr(rng.normal(size=(count, 3, 3)))
    q = q * np.sign(np.diagonal(r, axis1=1, axis2=2))[:, None, :]
    q[np.linalg.det(q) < 0, :, 0] *= -1
    return q


def render_many(client, volumes, rotations, size, chunk):
    """(len(volumes), len(rotations), H, W): every volume from every pose."""
    futures = [
        [
            client.submit(render_chunk, spec, rotations[i : i + chunk], size, pure=False)
            for i in range(0, len(rotations), chunk)
        ]
        for spec in volumes
    ]
    return np.stack([np.concatenate(client.gather(row)) for row in futures])


def main():
    from dask.distributed import Client, LocalCluster

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--volumes", nargs="+", default=[f"gaussians@48:{s}" for s in range(4)])
    ap.add_argument("--views", type=int, default=64)
    ap.add_argument("--chunk", type=int, default=16)
    ap.add_argument("--size", type=int, default=48)
    ap.add_argument("--workers", type=int, default=2)
    args = ap.parse_args()
    rotations = random_rotations(args.views)
    with LocalCluster(n_workers=args.workers, threads_per_worker=1, processes=True) as cluster:
        with Client(cluster) as client:
            images = render_many(client, args.volumes, rotations, args.size, args.chunk)
    print(f"{images.shape} {images.dtype}")


if __name__ == "__main__":
    main()
