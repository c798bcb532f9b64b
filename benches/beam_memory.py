"""Build time and memory (peak RSS, VmPeak) of a long cantilever System: ``scenes.cantilever(
elements=N)``, then optionally K more Systems of it (docs/scale.md, "Memory").

    .venv/bin/python benches/beam_memory.py 4096 5
"""
import resource, sys, time
import ukflex
from ukflex import scenes
n_el = int(sys.argv[1])
s = scenes.cantilever(elements=n_el)
t = time.perf_counter()
sysm = s.build()
dt = time.perf_counter() - t
print(f"elements={n_el} n={sysm.n_coords} m={sysm.n_constraints} build={dt:.2f}s maxrss={resource.getrusage(resource.RUSAGE_SELF).ru_maxrss/1024:.0f}MiB file={ukflex.__file__}")
vm = {l.split(':')[0]: l.split(':')[1].strip() for l in open('/proc/self/status') if l.startswith(('VmPeak', 'VmHWM'))}
print(f"  VmPeak={vm['VmPeak']} VmHWM={vm['VmHWM']}")
if len(sys.argv) > 2:
    systems = [s.build() for _ in range(int(sys.argv[2]))]
    vm = {l.split(':')[0]: l.split(':')[1].strip() for l in open('/proc/self/status') if l.startswith(('VmPeak', 'VmHWM'))}
    print(f"  {sys.argv[2]} more systems: VmPeak={vm['VmPeak']} VmHWM={vm['VmHWM']}")
