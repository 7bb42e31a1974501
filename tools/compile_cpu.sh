#!/usr/bin/env bash
# Compiler launcher that logs each compile's CPU time (docs/speed.md, "Build"): one line
# "user sys wall object" per compile appended to $COMPILE_CPU_LOG (default /tmp/compile_cpu.log).
# Configure with -DARTCAL_CCACHE=$PWD/tools/compile_cpu.sh (the launcher slot ccache uses).
out=unknown prev=""
for arg in "$@"; do
  if [ "$prev" = "-o" ]; then out=$arg; fi
  prev=$arg
done
exec /usr/bin/time -a -o "${COMPILE_CPU_LOG:-/tmp/compile_cpu.log}" -f "%U %S %e $out" "$@"
