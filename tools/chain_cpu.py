#!/usr/bin/env python3
"""The processor time of every process of the whole chain while it idles.

python tools/chain_cpu.py                   at 1 time (real time), 30 s
python tools/chain_cpu.py --speed 48        under libfaketime at 48 times, 30 s here

The chain (obsw_sim.chain, with the timers of obsw_sim.ditl_chain for that speed) comes up,
answers a ping, then idles (nothing asked of it) while every process's user and system time
is read over ``--seconds`` real seconds. One line per process: % of one core, its name.
"""

import argparse
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path[:0] = [os.path.join(ROOT, "micropython"), os.path.join(ROOT, "host")]

from obsw_sim import cpu, faketime  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawTextHelpFormatter
    )
    ap.add_argument("--speed", type=float, default=1.0, help="times faster (default 1)")
    ap.add_argument("--seconds", type=float, default=30.0, help="real seconds measured")
    args = ap.parse_args(argv)
    if args.speed != 1.0 and faketime.active() is None:
        env = dict(os.environ, **faketime.environment(args.speed))
        sys.stdout.flush()
        os.execve(sys.executable, [sys.executable] + sys.argv, env)
    from obsw_sim.chain import Chain
    from obsw_sim.ditl_chain import chain_settings

    work = tempfile.mkdtemp(prefix="obsw-cpu-")
    chain = Chain(work, processes=Chain.SAMPLE_PROCESSES, timeout=10.0 * max(1.0, args.speed / 2))
    chain_settings(chain, args.speed)
    with chain:
        chain.wait_up(600.0 * max(1.0, args.speed / 2))
        time.sleep(2.0 * args.speed)  # settled
        got = cpu.sample(cpu.tree(os.getpid()), args.seconds, lambda s: time.sleep(s * args.speed))
    total = 0.0
    for pid, (name, pc) in sorted(got.items(), key=lambda kv: -kv[1][1]):
        total += pc
        label = "the rig (station, ground, module supervisor)" if pid == os.getpid() else name
        print("%6.1f %%  %s" % (pc, label))
    print("%6.1f %%  in all, at %g times, over %g s here" % (total, args.speed, args.seconds))
    faketime.clean(os.getpid())
    return 0


if __name__ == "__main__":
    sys.exit(main())
