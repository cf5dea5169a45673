"""run(): step a world to a time, with a progress bar, recording chosen quantities."""

import sys
import time as _time

import numpy as np


class _TextProgress:
    """Plain-text progress on stderr when tqdm is not installed."""

    def __init__(self, total, desc):
        self.total, self.desc, self.n = total, desc, 0
        self.next_report = _time.monotonic() + 1.0

    def update(self, k):
        self.n += k
        now = _time.monotonic()
        if now >= self.next_report:
            sys.stderr.write(f"\r{self.desc}: {100.0 * self.n / max(self.total, 1):5.1f} %")
            sys.stderr.flush()
            self.next_report = now + 0.5

    def close(self):
        sys.stderr.write(f"\r{self.desc}: done ({self.n} steps)\n")
        sys.stderr.flush()


def _progress(total, desc, enabled):
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:
        return _TextProgress(total, desc)
    return tqdm(total=total, desc=desc, unit="step")


def run(world, t_end, record=None, every=None, progress=True, desc="wrapsim"):
    """Step `world` until its time reaches t_end (s).

    record: {name: callable()} whose results (a float or an array) are sampled at the start and
    every `every` seconds (default: every step) and at the end. progress: a tqdm bar when tqdm
    is installed, plain text on stderr otherwise; False for none.
    Returns {"t": times (k,), name: values (k, ...)} as numpy arrays.
    """
    record = dict(record or {})
    dt = world.dt
    total = max(int(round((t_end - world.time) / dt)), 0)
    chunk = 1 if every is None else max(int(round(every / dt)), 1)
    if not record:  # nothing to sample: step in chunks that keep the bar moving
        chunk = max(total // 200, 1) if every is None else chunk
    times, samples = [], {k: [] for k in record}

    def sample():
        times.append(world.time)
        for k, fn in record.items():
            samples[k].append(np.array(fn(), dtype=float, copy=True))

    bar = _progress(total, desc, progress)
    try:
        if record:
            sample()
        done = 0
        while done < total:
            n = min(chunk, total - done)
            world.step(n)
            done += n
            if bar is not None:
                bar.update(n)
            if record and (done % chunk == 0 or done == total):
                sample()
    finally:
        if bar is not None:
            bar.close()
    out = {"t": np.array(times)}
    for k, v in samples.items():
        out[k] = np.stack(v) if v else np.empty(0)
    return out
