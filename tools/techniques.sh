# shellcheck shell=bash
# The techniques that the main job (tools/dev.sh run) and the fidelity
# benchmark (tools/fidelity.sh) compare, named in this one place, and the
# table both print. Sourced; LIMN names the limn binary. The default
# technique is not named here: it is the first of scripts/pp.lua's
# Techniques, what `limn capture` renders without --tech, so a new default
# needs no edit here.

# shellcheck disable=SC2034 # used by the scripts that source this file
LIMN_BASELINE=dl+esm  # direct light with shadows: the references have shadows

# The default technique (the pipeline's first).
limn_default_technique() {
  "$LIMN" capture --list-options | sed -n 's/^techniques: \([^ ]*\).*/\1/p'
}

# An option's default value, empty when the pipeline has no such option.
limn_option_default() {
  "$LIMN" capture --list-options | sed -n 's/^options: //p' | tr ',' '\n' | sed -n "s/^ *$1=//p"
}

# Sweep specs (limn report --sweep); each setting starts from the defaults.
# The seed's image-space radiosity (isr.mode = "seed" once the pipeline has
# the option; before that isr+esm is the seed's).
limn_seed_isr_spec() {
  if [ -n "$(limn_option_default isr.mode)" ]; then echo "isr+esm:isr.mode=seed"; else echo "isr+esm"; fi
}
# The default technique at its defaults.
limn_default_spec() {
  local tech mode
  tech=$(limn_default_technique)
  mode=$(limn_option_default isr.mode)
  if [ -n "$mode" ]; then echo "$tech:isr.mode=$mode"; else echo "$tech"; fi
}

# limn_gi_report [--targets] OUT JOB FRAMES NAME=SPEC... : limn report of JOB
# into OUT with the first NAME=SPEC as the baseline and the others as sweeps
# (a spec given twice is rendered once), then a table per NAME over the views:
# mean error, mean ms, share of the baseline's indirect error removed (mean
# over views), views improved, views whose Pearson rose, time over the
# baseline's (same run). --targets adds the GI targets with PASS or FAIL
# (for the NAMEs default, ssdo+esm and ssao+esm; rsm+esm, vpl+esm, combined and lpv+esm when given).
limn_gi_report() {
  local targets=0
  [ "$1" = --targets ] && targets=1 && shift
  local out=$1 job=$2 frames=$3
  shift 3
  local names=() specs=() uniq=() sweeps=() index=() pair s i
  for pair in "$@"; do names+=("${pair%%=*}"); specs+=("${pair#*=}"); done
  for s in "${specs[@]}"; do
    case " ${uniq[*]-} " in *" $s "*) ;; *) uniq+=("$s"); [ ${#uniq[@]} = 1 ] || sweeps+=(--sweep "$s") ;; esac
  done
  for s in "${specs[@]}"; do
    for i in "${!uniq[@]}"; do [ "${uniq[$i]}" = "$s" ] && index+=("$i"); done
  done
  "$LIMN" report --job "$job" --baseline "${specs[0]}" "${sweeps[@]}" --out "$out" --frames "$frames" \
    --warmup 1 --quiet || return
  echo
  # The CSV's rows go view by view, the settings in order.
  awk -F, -v S="${#uniq[@]}" -v names="$(IFS='|'; echo "${names[*]}")" -v idx="${index[*]}" \
      -v specs="$(IFS='|'; echo "${specs[*]}")" -v targets=$targets '
  NR > 1 {
    k = NR - 2; s = k % S; v = int(k / S); V = v + 1
    e[s, v] = $8; p[s, v] = $11; ms[s, v] = $14; fl[v] = $16; sh[s, v] = $17
  }
  END {
    n = split(names, nm, "|"); split(idx, ix, " "); split(specs, sp, "|")
    for (s = 0; s < S; s++) {
      E[s] = M[s] = SH[s] = SN[s] = UP[s] = DOWN[s] = PR[s] = 0
      for (v = 0; v < V; v++) {
        E[s] += e[s, v] / V; M[s] += ms[s, v] / V
        if (s == 0) continue
        if (sh[s, v] != "n/a") { SH[s] += sh[s, v]; SN[s]++ }
        UP[s] += e[s, v] < e[0, v]; DOWN[s] += e[s, v] > e[0, v]; PR[s] += p[s, v] > p[0, v]
      }
      if (SN[s]) SH[s] /= SN[s]
    }
    for (v = 0; v < V; v++) floor += fl[v] / V
    printf "%d views; direct-only floor (%s against POV-Ray without radiosity): mean error %.5f\n\n", V, nm[1], floor
    printf "%-10s %-26s %9s %8s %8s %8s %8s %6s\n", "technique", "setting", "mean err", "ms", "indir.%", "improved",
           "Pearson+", "time x"
    for (i = 1; i <= n; i++) {
      s = ix[i]
      if (s == 0) { printf "%-10s %-26s %9.5f %8.2f\n", nm[i], sp[i], E[s], M[s]; continue }
      printf "%-10s %-26s %9.5f %8.2f %8s %4d/%-3d %4d/%-3d %6.2f\n", nm[i], sp[i], E[s], M[s],
             (SN[s] ? sprintf("%.1f", SH[s]) : "n/a"), UP[s], V, PR[s], V, (M[0] > 0 ? M[s] / M[0] : 0)
    }
    if (!targets) exit
    for (i = 1; i <= n; i++) if (nm[i] == "default") d = ix[i]; else if (nm[i] == "ssdo+esm") so = ix[i]; else if (nm[i] == "ssao+esm") sa = ix[i]
    for (i = 1; i <= n; i++) if (nm[i] == "rsm+esm") rs = ix[i]; else if (nm[i] == "vpl+esm") vp = ix[i]; else if (nm[i] == "combined") co = ix[i]; else if (nm[i] == "lpv+esm") lp = ix[i]
    b = nm[1]
    printf "\ntargets:\n"
    printf "  %s  the default removes at least 40%% of %s'"'"'s indirect error (mean over views): %s\n",
           (SN[d] && SH[d] >= 40 ? "PASS" : "FAIL"), b, (SN[d] ? sprintf("%.1f%%", SH[d]) : "n/a")
    printf "  %s  the default improves every view: %d of %d\n", (UP[d] == V ? "PASS" : "FAIL"), UP[d], V
    printf "  %s  the default raises Pearson in every view: %d of %d\n", (PR[d] == V ? "PASS" : "FAIL"), PR[d], V
    r = M[0] > 0 ? M[d] / M[0] : 0
    printf "  %s  the default takes at most 2x %s'"'"'s time: %.2fx\n", (r <= 2 ? "PASS" : "FAIL"), b, r
    printf "  %s  ssdo+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
           (DOWN[so] == 0 ? "PASS" : "FAIL"), DOWN[so], V, E[0], E[so]
    printf "  %s  ssao+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
           (DOWN[sa] == 0 ? "PASS" : "FAIL"), DOWN[sa], V, E[0], E[sa]
    if (co) {
      printf "  %s  combined (isr+rsm+esm) removes at least 60%% of %s'"'"'s indirect error: %s\n",
             (SN[co] && SH[co] >= 60 ? "PASS" : "FAIL"), b, (SN[co] ? sprintf("%.1f%%", SH[co]) : "n/a")
      printf "  %s  combined improves every view: %d of %d\n", (UP[co] == V ? "PASS" : "FAIL"), UP[co], V
    }
    if (rs) printf "  %s  rsm+esm removes at least 30%%: %s\n", (SN[rs] && SH[rs] >= 30 ? "PASS" : "FAIL"),
                   (SN[rs] ? sprintf("%.1f%%", SH[rs]) : "n/a")
    if (vp) printf "  %s  vpl+esm removes at least 30%%: %s\n", (SN[vp] && SH[vp] >= 30 ? "PASS" : "FAIL"),
                   (SN[vp] ? sprintf("%.1f%%", SH[vp]) : "n/a")
    if (lp) printf "  %s  lpv+esm removes at least 30%%: %s\n", (SN[lp] && SH[lp] >= 30 ? "PASS" : "FAIL"),
                   (SN[lp] ? sprintf("%.1f%%", SH[lp]) : "n/a")
  }' "$out/report.csv"
  echo
  echo "mean err: seed eq 19, mean over the views; ms: mean time per frame; indir.%: share of ${names[0]}'s"
  echo "indirect error removed, mean over the views; improved: views with a lower error than ${names[0]};"
  echo "Pearson+: views whose Pearson rose; time x: ms over ${names[0]}'s, measured in the same run."
  echo "report: $out/report.md, $out/report.svg"
}
