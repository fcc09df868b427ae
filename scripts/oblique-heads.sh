#!/usr/bin/env bash
# The planner's choices on whole real heads, off axis, as `fvr` makes them:
# for each head and --accuracy 40, 50 and 60, the chosen configuration, its
# prediction and the SNR of six oblique views against the same view
# rendered with kb6 on 2x padding in f64 (the reference that agrees with the
# ideal slice DFT to 112-122 dB: docs/accuracy.md). Prints a Markdown table.
#
# Usage: FVR_CT_HEAD=$(bash scripts/fetch-ct-head.sh) \
#        FVR_MRI_HEAD=$(bash scripts/fetch-mri-head.sh) bash scripts/oblique-heads.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --locked --release -p fvr-host >&2
fvr="${CARGO_TARGET_DIR:-target}/release/fvr"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
heads=(brainsmall)
[ -n "${FVR_CT_HEAD:-}" ] && heads+=(ct-head)
[ -n "${FVR_MRI_HEAD:-}" ] && heads+=(mri-head)
dirs=("1,1,1" "1,1,0" "1,0.6,0.3" "-0.3,1,0.8" "0,1,1" "1,0,1")
echo "| volume | --accuracy | chosen | predicted dB | measured dB (${dirs[*]}) |"
echo "|---|---|---|---|---|"
for v in "${heads[@]}"; do
    for d in "${dirs[@]}"; do
        "$fvr" render "$v" --dir "$d" --filter kb6 --oversample 2 --precision f64 \
            --out "$work/ref-$d.nrrd" >/dev/null
    done
    for acc in 40 50 60; do
        measured=()
        for d in "${dirs[@]}"; do
            json=$("$fvr" render "$v" --dir "$d" --accuracy "$acc" --out "$work/t.nrrd" --stats-json | tail -1)
            snr=$("$fvr" compare "$work/ref-$d.nrrd" "$work/t.nrrd" | sed -n 's/.*: \([-0-9.inf]*\) dB.*/\1/p')
            measured+=("$snr")
        done
        python3 - "$json" "$v" "$acc" "${measured[*]}" <<'PY'
import json, sys
a = json.loads(sys.argv[1])["accuracy"]
chosen = "{} σ{} {}".format(a["filter"], a["oversample"], a["precision"])
print("| {} | {} | {} | {:.1f} | {} |".format(
    sys.argv[2], sys.argv[3], chosen, a["predicted_db"], ", ".join(sys.argv[4].split())))
PY
    done
done
