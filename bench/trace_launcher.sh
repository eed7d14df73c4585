#!/bin/bash
# A CMake compiler and linker launcher for bench/cpp_cores_sim.py: runs the command and appends its
# span, kind and output file to $ROC_TRACE_LOG as a JSON line (one write, so concurrent jobs do not mix).
#   -DCMAKE_CXX_COMPILER_LAUNCHER="bench/trace_launcher.sh;compile" (and ";link" for the linker)
kind=$1
shift
start=$(date +%s.%N)
"$@"
status=$?
end=$(date +%s.%N)
out=""
previous=""
for argument in "$@"; do
  [ "$previous" = "-o" ] && out=$argument
  previous=$argument
done
printf '{"start": %s, "end": %s, "cwd": "%s", "out": "%s", "kind": "%s"}\n' \
  "$start" "$end" "$PWD" "$out" "$kind" >> "$ROC_TRACE_LOG"
exit $status
