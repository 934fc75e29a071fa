#!/usr/bin/env bash
# Compiles the checked-in generated models for a Cortex-M4F (the Crazyflie's STM32F405 class:
# single-precision FPU) the way firmware would use them (examples/firmware/model_unit.cpp,
# float, -O2, no exceptions, no RTTI) and reports, per model and entry point, the code size,
# what the object still needs from outside, and whether any double-precision arithmetic is
# left (soft-float calls on this FPU, or .f64 instructions). Fails on any of these, or if the
# object needs the heap, exceptions or RTTI. The stack column is gcc's -fstack-usage: each
# entry point's own frame plus that of the rhs it calls (what the C library's sinf, cosf,
# powf and logf take comes on top); a frame of dynamic size fails the check.
#   scripts/firmware_check.sh
# Installs the Debian cross compiler (gcc-arm-none-eabi) if it is missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v arm-none-eabi-g++ > /dev/null; then
  echo "installing gcc-arm-none-eabi (Debian) ..." >&2
  sudo_cmd=""; [ "$(id -u)" = 0 ] || sudo_cmd="sudo"
  $sudo_cmd apt-get install -y -q gcc-arm-none-eabi libstdc++-arm-none-eabi-newlib > /dev/null
fi
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
flags=(-std=c++17 -mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -O2 -ffunction-sections
       -fno-exceptions -fno-rtti -fstack-usage -Wall -Wdouble-promotion -Werror=double-promotion -Wno-unused-variable)
status=0
echo "| model | rhs, f only [B] | rhs, f + Jacobians [B] | precompute [B] | precomputed values in RAM [B] | stack: f / f + Jacobians / precompute [B] | external symbols | double-precision calls |"
echo "|---|---|---|---|---|---|---|---|"
for dir in generated/*/; do
  name=$(basename "$dir")
  obj="$tmp/$name.o"
  if ! arm-none-eabi-g++ "${flags[@]}" -DMODEL_HEADER="\"$PWD/${dir}model.hpp\"" \
       -DMODEL_NAMESPACE="quadgen_generated::$name" -c examples/firmware/model_unit.cpp -o "$obj" 2> "$tmp/$name.err"; then
    echo "| $name | does not compile: $(head -c 300 "$tmp/$name.err" | tr '\n' ' ') |"
    status=1
    continue
  fi
  size_of() {  # bytes of the symbols whose demangled line matches $1 (nm's sizes are hexadecimal)
    local total=0 hex
    for hex in $(arm-none-eabi-nm -S -C "$obj" | grep -E "$1" | awk '{ print $2 }'); do total=$((total + 16#$hex)); done
    echo "$total"
  }
  # The two instantiations of rhs<float>: f only (5 arguments) and with the Jacobians (8).
  f_only=$(size_of 'rhs<float>\(([^,]*,){4}[^,]*\)$')
  f_jac=$(size_of 'rhs<float>\(([^,]*,){7}[^,]*\)$')
  # gcc writes the frames next to the object ($name.su): "file:line:col:signature<TAB>bytes<TAB>kind".
  frame_of() {  # the largest frame whose signature matches $1; 0 when inlined away
    { grep -E "$1" "$tmp/$name.su" || true; } | awk -F'\t' 'BEGIN { m = 0 } $2 > m { m = $2 } END { print m }'
  }
  rhs_sig='rhs\(([^,]*,){%d}[^,]*\) \[with Scalar = float\]'
  stack="$(( $(frame_of 'void quadgen_f\(') + $(frame_of "$(printf "$rhs_sig" 4)") ))"
  stack+=" / $(( $(frame_of 'void quadgen_f_jacobians\(') + $(frame_of "$(printf "$rhs_sig" 7)") ))"
  stack+=" / $(( $(frame_of 'void quadgen_precompute\(') + $(frame_of 'precompute\(const Scalar\*, Precomputed<Scalar>\*\) \[with Scalar = float\]') ))"
  if grep -q -P '\tdynamic' "$tmp/$name.su"; then stack+=" — DYNAMIC"; status=1; fi
  undefined=$(arm-none-eabi-nm -u "$obj" | awk '{print $2}' | sort -u)
  # Double precision either as soft-float calls (this FPU has none for doubles) or as .f64
  # instructions in the disassembly (there should be neither).
  doubles=$(( $(echo "$undefined" | grep -c '^__aeabi_d' || true) + $(arm-none-eabi-objdump -d "$obj" | grep -c '\.f64' || true) ))
  [ "$doubles" -gt 0 ] && status=1
  forbidden=$(echo "$undefined" | grep -E '^(malloc|free|_Znw|_Zdl|_Zna|_Zda|__cxa_|__gxx_personality|_Unwind)' || true)
  [ -n "$forbidden" ] && status=1
  echo "| $name | $f_only | $f_jac | $(size_of ' quadgen_precompute$') | $(size_of ' quadgen_pre$') | $stack | $(echo ${undefined:-none} | tr ' ' ',')${forbidden:+ — FORBIDDEN: $forbidden} | $doubles |"
done
exit $status
