#!/usr/bin/env bash
# The large fuzz run (`docs/robustness.md`, "The fuzz suite"): 10⁶ mutated inputs per format through the library's
# parsers and evaluators (`hylc fuzz`; the CI runs 600 per format in tests/fuzz.rs). Writes the counts table to
# validation/fuzz.md. CASES=N overrides the count. Takes hours on 2 cores for the default 10⁶ per format.
set -euo pipefail
cd "$(dirname "$0")/.."
CASES="${CASES:-1000000}"
cargo build --release
{
  echo "Written by \`validation/fuzz.sh\` (\`hylc fuzz --cases $CASES --seed 1\`) on $(date -u +%Y-%m-%d)."
  echo
  target/release/hylc fuzz --cases "$CASES" --seed 1
} | tee validation/fuzz.md
