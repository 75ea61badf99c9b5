#!/usr/bin/env bash
# tools/fidelity.sh: how close each GI technique comes to POV-Ray on the
# reference set (data/jobs/reference.lua), and at what cost. A benchmark, not
# a test: it prints figures and the targets of the project's GI work with
# PASS or FAIL, and exits 0 when the run completes.
#   BUILD_DIR  the build (default build)
#   OUT        the report's folder (default out/fidelity)
#   FRAMES     timed frames per image, after one warm-up (default 3)
#   JOB        the job (default data/jobs/reference.lua)
# References (radiosity and direct-only) are rendered once and cached under
# out/reference; `limn report` writes report.md/.csv/.json/.svg to OUT.
set -euo pipefail
cd "$(dirname "$0")/.."
LIMN=${BUILD_DIR:-build}/limn
out=${OUT:-out/fidelity}
job=${JOB:-data/jobs/reference.lua}
[ -x "$LIMN" ] || { echo "fidelity: no $LIMN (build first: tools/dev.sh build)" >&2; exit 2; }
# shellcheck source=tools/techniques.sh
. tools/techniques.sh

# The settings, baseline first: name and sweep spec; a spec given twice is rendered once.
names=("$LIMN_BASELINE" "seed ISR" "ssdo+esm" "ssao+esm" "default")
specs=("$LIMN_BASELINE" "$(limn_seed_isr_spec)" ssdo+esm ssao+esm "$(limn_default_spec)")
sweeps=() uniq=()
for s in "${specs[@]}"; do
  case " ${uniq[*]-} " in *" $s "*) ;; *) uniq+=("$s"); [ "$s" = "$LIMN_BASELINE" ] || sweeps+=(--sweep "$s") ;; esac
done
index=()  # each name's setting in the report
for s in "${specs[@]}"; do
  for i in "${!uniq[@]}"; do [ "${uniq[$i]}" = "$s" ] && index+=("$i"); done
done

"$LIMN" report --job "$job" --baseline "$LIMN_BASELINE" "${sweeps[@]}" --out "$out" \
  --frames "${FRAMES:-3}" --warmup 1 --quiet
echo

# Per setting over the views (the CSV's rows go view by view, the settings in order):
# mean error, mean share of indirect error removed, views improved / worse than
# the baseline, views whose Pearson rose, mean ms over the baseline's.
awk -F, -v S="${#uniq[@]}" -v names="$(IFS='|'; echo "${names[*]}")" -v idx="${index[*]}" \
    -v specs="$(IFS='|'; echo "${specs[*]}")" -v base="$LIMN_BASELINE" '
NR > 1 {
  k = NR - 2; s = k % S; v = int(k / S); V = v + 1
  e[s, v] = $8; p[s, v] = $11; ms[s, v] = $14; fl[v] = $16; sh[s, v] = $17
}
END {
  n = split(names, nm, "|"); split(idx, ix, " "); split(specs, sp, "|")
  for (s = 0; s < S; s++) {
    E[s] = M[s] = 0; SH[s] = SN[s] = UP[s] = DOWN[s] = PR[s] = 0
    for (v = 0; v < V; v++) {
      E[s] += e[s, v] / V; M[s] += ms[s, v] / V
      if (sh[s, v] != "n/a" && s > 0) { SH[s] += sh[s, v]; SN[s]++ }
      if (s > 0) { UP[s] += e[s, v] < e[0, v]; DOWN[s] += e[s, v] > e[0, v]; PR[s] += p[s, v] > p[0, v] }
    }
    if (SN[s]) SH[s] /= SN[s]
  }
  floor = 0
  for (v = 0; v < V; v++) floor += fl[v] / V
  printf "%d views; direct-only floor (%s against POV-Ray without radiosity): mean error %.5f\n\n", V, base, floor
  printf "%-10s %-28s %10s %9s %9s %9s %9s\n", "technique", "setting", "mean err", "indir. %", "improved", "Pearson+", "time x"
  for (i = 1; i <= n; i++) {
    s = ix[i]
    if (s == 0) { printf "%-10s %-28s %10.5f %9s %9s %9s %9.2f\n", nm[i], sp[i], E[s], "", "", "", 1; continue }
    printf "%-10s %-28s %10.5f %9s %5d/%-3d %5d/%-3d %9.2f\n", nm[i], sp[i], E[s], SN[s] ? sprintf("%.1f", SH[s]) : "n/a",
           UP[s], V, PR[s], V, (M[0] > 0 ? M[s] / M[0] : 0)
  }
  # The targets (issue 14): the default technique, SSDO and SSAO.
  printf "\ntargets:\n"
  for (i = 1; i <= n; i++) if (nm[i] == "default") d = ix[i]; else if (nm[i] == "ssdo+esm") so = ix[i]; else if (nm[i] == "ssao+esm") sa = ix[i]
  t = SN[d] && SH[d] >= 40
  printf "  %s  the default removes at least 40%% of %s'"'"'s indirect error (mean over views): %s\n", t ? "PASS" : "FAIL", base, SN[d] ? sprintf("%.1f%%", SH[d]) : "n/a"
  printf "  %s  the default improves every view: %d of %d\n", UP[d] == V ? "PASS" : "FAIL", UP[d], V
  printf "  %s  the default raises Pearson in every view: %d of %d\n", PR[d] == V ? "PASS" : "FAIL", PR[d], V
  r = M[0] > 0 ? M[d] / M[0] : 0
  printf "  %s  the default takes at most 2x %s'"'"'s time: %.2fx\n", r <= 2 ? "PASS" : "FAIL", base, r
  printf "  %s  ssdo+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
         DOWN[so] == 0 ? "PASS" : "FAIL", DOWN[so], V, E[0], E[so]
  printf "  %s  ssao+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
         DOWN[sa] == 0 ? "PASS" : "FAIL", DOWN[sa], V, E[0], E[sa]
}' "$out/report.csv"
echo
echo "columns: mean error (seed eq 19) over the views; share of $LIMN_BASELINE's indirect error removed, mean over views;"
echo "views with a lower error than $LIMN_BASELINE; views whose Pearson rose; mean time per frame over $LIMN_BASELINE's (same run)."
echo "report: $out/report.md, $out/report.svg"
