#!/usr/bin/env bash
# The project's own code must not use 512-bit (zmm) registers, not even in
# the decoder's AVX-512 instance (`tcb_runtime::pack::store::v4`): on Intel
# cores one 512-bit instruction in a loop slows the 256-bit work around it
# (vector port 1 stops while 512-bit work is in flight). LLVM's vectorizer
# joins 256-bit work into 512-bit operations in functions compiled with
# `avx512f` where the code leaves it room (array lanes); this catches it.
#
#   tools/check/no-512-bit.sh [BINARY]   (default target/release/tcb-bench)
set -euo pipefail
bin=${1:-target/release/tcb-bench}
found=$(objdump -d --no-show-raw-insn -C "$bin" |
  awk '/^[0-9a-f]+ <.*>:$/ { f = $0 } /zmm/ && f ~ /tcb_(runtime|core)::/ { n[f]++ }
       END { for (k in n) print n[k], k }')
if [ -n "$found" ]; then
  echo "512-bit registers in the project's code ($bin):" >&2
  echo "$found" >&2
  exit 1
fi
echo "no 512-bit registers in tcb_runtime or tcb_core ($bin)"
