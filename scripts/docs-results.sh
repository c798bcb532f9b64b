#!/usr/bin/env bash
# Regenerate the committed outputs under docs/results/ (docs/paper.md, docs/work-precision.md).
# Long: the Table 1 analogue in full mode and the work-precision grids take 1-3 hours on 2 cores.
# Usage: bash scripts/docs-results.sh [paper|wp|elements|animation ...]   (default: all)
set -euo pipefail
cd "$(dirname "$0")/.."
export MPLBACKEND=Agg
U=.venv/bin/ukflex
parts=("$@"); [ ${#parts[@]} -eq 0 ] && parts=(paper animation wp elements)
for part in "${parts[@]}"; do
  case "$part" in
    paper)
      $U paper --out docs/results/paper --samples 1001 --table full --no-progress
      $U paper --out docs/results/paper-n8 --elements 8 --method DOP853 --samples 1001 --table none --no-progress ;;
    animation)
      tmp=$(mktemp -d)
      $U run examples/slider_crank.toml --out "$tmp" --animate --frames 100 --no-progress
      mkdir -p docs/results/run
      cp "$tmp/slider_crank.png" "$tmp/slider_crank.gif" docs/results/run/
      rm -rf "$tmp" ;;
    wp)
      $U bench work-precision --out docs/results/work-precision ;;
    elements)
      $U bench elements --out docs/results/elements --reference-elements 16 ;;
    *) echo "unknown part $part" >&2; exit 2 ;;
  esac
done
