#!/usr/bin/env bash
# Regenerates the cost-and-error table of docs/accuracy-mcu.md: builds the measurement program
# for the Cortex-M4F and runs it on QEMU's mps2-an386 with -icount shift=0 (one instruction per
# virtual nanosecond), printing Markdown rows. Needs qemu-system-arm.
set -euo pipefail
cd "$(dirname "$0")"
cargo build --release --bin cost
qemu-system-arm -cpu cortex-m4 -machine mps2-an386 -nographic \
  -semihosting-config enable=on,target=native -icount shift=0 \
  -kernel target/thumbv7em-none-eabihf/release/cost
