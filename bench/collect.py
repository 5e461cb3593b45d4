"""Collect the benchmark fragments (bench/*_results.md) into bench/RESULTS.md.

Each bench script writes its own fragment with the machine, medians and ratios to the
baseline measured in the same run; this script only concatenates them in a fixed order.

    python bench/collect.py
"""
from __future__ import annotations

import os
from pathlib import Path

HERE = Path(__file__).parent
ORDER = ["tables", "squeeze", "trapped", "first_call", "alloc", "seal", "sweep", "run_memory", "fuzz", "fuzz_extensions", "extensions",
         "calibration_integration", "layout", "kernel_inputs", "compile"]
#: fragments whose script name differs from bench_<name>.py
SCRIPT = {"run_memory": "bench_run_memory.py",
          "layout": "bench_tables.py --speed, bench_squeeze.py, bench_seal.py"}
HEADER = """# fastcontact benchmark results

Numbers are produced by the scripts in `bench/` (each section names its script). Machines are
shared and noisy: compare the ratios (measured in the same run), not absolute seconds across
sections. Speed and accuracy targets are checked here, never in timed unit tests.
"""


def main():
    parts = [HEADER]
    for name in ORDER:
        frag = HERE / f"{name}_results.md"
        if frag.exists():
            parts.append(f"<!-- from bench/{frag.name} (bench/{SCRIPT.get(name, f'bench_{name}.py')}) -->\n"
                         + frag.read_text())
        else:
            parts.append(f"## {name}\n\nNot yet measured: run `python bench/bench_{name}.py`.\n")
    out = HERE / "RESULTS.md"
    tmp = out.with_suffix(".md.tmp")
    tmp.write_text("\n".join(parts))
    os.replace(tmp, out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
