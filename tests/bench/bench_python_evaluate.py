"""Cost of evaluate from Python against the C++ benchmark (issue 23; docs/python.md, "Cost").

  PYTHONPATH=build/python /usr/bin/python3 tests/bench/bench_python_evaluate.py [CALLS]
  build/tests/bench/bench_evaluator --benchmark_filter=Paper2R     (the C++ twins)

Prints the time per call of, on plans/paper-2r-5bars.json:
  prepared   artcal.Evaluator(plan).tip(): what tests/bench/bench_evaluator measures in C++
             (PlanEvaluator::tip, the workspace prepared once);
  evaluate   plan.evaluate(per_configuration=False): the whole `artcal evaluate --json` (workspace
             sampling, V_p, tip, the reach profile, the JSON document as a dict);
  evaluate+  plan.evaluate(): the same plus the per-configuration tip arrays.
Not a test: timings depend on the machine and its load.
"""

import sys
import time

import artcal


def per_call_us(call, calls: int) -> str:
    """Wall and CPU time per call (us), as Google Benchmark's Time and CPU columns."""
    call()  # warm
    wall, cpu = time.perf_counter(), time.process_time()
    for _ in range(calls):
        call()
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return f"{wall / calls * 1e6:9.2f} us wall {cpu / calls * 1e6:9.2f} us CPU per call"


def main() -> None:
    calls = int(sys.argv[1]) if len(sys.argv) > 1 else 10_000
    plan = artcal.Plan("plans/paper-2r-5bars.json")
    evaluator = artcal.Evaluator(plan)
    print(f"calls {calls}")
    print(f"prepared   {per_call_us(evaluator.tip, calls)}")
    print(f"evaluate   {per_call_us(lambda: plan.evaluate(per_configuration=False), calls)}")
    print(f"evaluate+  {per_call_us(plan.evaluate, max(calls // 10, 1))}")


if __name__ == "__main__":
    main()
