"""The benchmarks' timers: one call's median cost, and whole runs timed round-robin (so
that the load bursts of a shared machine hit every contender alike)."""
import gc
import statistics
import time
from time import perf_counter


def per_call(fn, budget=0.05, rounds=15, most=1 << 20):
    """Median us per call of ``fn()`` over ``rounds`` blocks of about ``budget`` s (at most
    ``most`` calls a block); the garbage collector off while timing."""
    fn()
    n = 1
    while True:
        t0 = perf_counter()
        for _ in range(n):
            fn()
        if perf_counter() - t0 > budget / 4 or n > most:
            break
        n *= 2
    out = []
    gc.disable()
    try:
        for _ in range(rounds):
            t0 = perf_counter()
            for _ in range(n):
                fn()
            out.append((perf_counter() - t0) / n * 1e6)
    finally:
        gc.enable()
    return float(statistics.median(out))


def interleaved_cpu(runs, rounds):
    """``{name: [CPU seconds]}`` of whole calls ``runs = {name: fn}``, one call each per
    round, the order rotated round by round, garbage collector off."""
    cpu = {k: [] for k in runs}
    keys = list(runs)
    gc.collect()
    gc.disable()
    try:
        for r in range(rounds):
            for k in keys[r % len(keys):] + keys[:r % len(keys)]:
                c0 = time.process_time()
                runs[k]()
                cpu[k].append(time.process_time() - c0)
    finally:
        gc.enable()
    return cpu
