#!/usr/bin/env bash
# The whole test suite: build, then ctest (unit, diagnostics, golden, conformance,
# guide, CLI and Python tests); then the unit tests again under AddressSanitizer
# and UndefinedBehaviorSanitizer (scripts/sanitize.sh, a clang-14 tree), and a
# short run of every libFuzzer target under both sanitizers (scripts/fuzz.sh,
# AUTUMN_FUZZ_SECONDS each, default 40). The conformance corpus is read from
# ../shared (AUTUMN_SHARED_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/bootstrap.sh
(cd build && ctest --output-on-failure -j2)
echo "== unit tests under ASan+UBSan (scripts/sanitize.sh)"
bash scripts/sanitize.sh
for target in frontend interp emit task; do
  echo "== fuzz smoke: $target, ${AUTUMN_FUZZ_SECONDS:-40} s (scripts/fuzz.sh)"
  bash scripts/fuzz.sh "$target" "${AUTUMN_FUZZ_SECONDS:-40}"
done
