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
# The default technique at its defaults (an ISR default names its mode, so
# that it is not taken for the seed ISR's spec).
limn_default_spec() {
  local tech mode
  tech=$(limn_default_technique)
  case $tech in isr*) mode=$(limn_option_default isr.mode) ;; *) mode= ;; esac
  if [ -n "$mode" ]; then echo "$tech:isr.mode=$mode"; else echo "$tech"; fi
}

# limn_gi_report [--targets] [--cycles] [--refs DIR] OUT JOB FRAMES NAME=SPEC... : limn report of JOB
# into OUT against POV-Ray with the first NAME=SPEC as the baseline and the others as sweeps (a spec
# given twice is rendered once), then a table per NAME over the views: mean error, mean ms, share of
# the baseline's indirect error removed (mean over views), views improved, views whose Pearson rose,
# time over the baseline's (same run). --cycles adds the same columns against Cycles (a second
# report into OUT/cycles with --cached-refs: over the views whose Cycles references are cached in
# DIR, default out/reference; a line names the command that renders the others) and each Cycles
# reference's noise. --targets adds the GI targets with PASS or FAIL (for the NAMEs default,
# ssdo+esm and ssao+esm; rsm+esm, vpl+esm, combined and lpv+esm when given). --moving SIZE adds each
# setting's moving-camera frame over the baseline's at SIZE (MOTION=1 tools/gi_time.sh over the reference
# set's scenes, MOVING_ROUNDS rounds, default 2), and the targets' time budgets are judged on it: issue
# 32 states them for a moving camera at 256x192, where no settled frame skips the GI passes.
limn_gi_report() {
  local targets=0 cycles=0 refs=out/reference moving=""
  while :; do
    case $1 in
      --targets) targets=1; shift ;;
      --cycles) cycles=1; shift ;;
      --refs) refs=$2; shift 2 ;;
      --moving) moving=$2; shift 2 ;;
      *) break ;;
    esac
  done
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
  local report=("$LIMN" report --job "$job" --refs "$refs" --baseline "${specs[0]}" "${sweeps[@]}" --frames "$frames"
                --warmup 1 --quiet)
  "${report[@]}" --out "$out" || return
  # Moving-camera ratios, one per setting in uniq's order (gi_time.sh separates options by commas).
  local mov=""
  if [ -n "$moving" ]; then
    local gt
    gt=$(TECHS="${uniq[*]//;/,}" SIZE="$moving" MOTION=1 ROUNDS="${MOVING_ROUNDS:-2}" \
         BUILD_DIR="$(dirname "$LIMN")" tools/gi_time.sh) || return
    for s in "${uniq[@]}"; do
      mov+="$(awk -v t="${s//;/,}" '$1 == t { print $3; exit }' <<< "$gt")|"
    done
  fi
  # Against Cycles: the same images (each setting starts afresh), compared with the cached references.
  local csvs=("$out/report.csv") note=""
  if [ $cycles = 1 ]; then
    mkdir -p "$out/cycles"
    local render="$LIMN reference --job $job --refs $refs --renderer cycles, again with --bounces 0 and"
    render+=" with --seed 1 (minutes a view)"
    if "${report[@]}" --out "$out/cycles" --renderer cycles --cached-refs 2>"$out/cycles/stderr"; then
      csvs+=("$out/cycles/report.csv")
      local left
      left=$(grep -c " left out: " "$out/cycles/stderr" || true) # grep -c exits 1 on none
      [ "$left" = 0 ] || note="Cycles: $left views without cached references left out; render them with $render"
    elif grep -q "no view has its references cached" "$out/cycles/stderr"; then
      note="Cycles: no references cached in $refs (POV-Ray alone below); render them with $render"
    else
      note="Cycles: no column: $(grep -m1 . "$out/cycles/stderr")"
    fi
  fi
  echo
  [ -z "$note" ] || echo "$note"
  # The CSVs' rows go view by view, the settings in order; the first CSV is POV-Ray's, a second Cycles'.
  awk -F, -v S="${#uniq[@]}" -v names="$(IFS='|'; echo "${names[*]}")" -v idx="${index[*]}" \
      -v specs="$(IFS='|'; echo "${specs[*]}")" -v targets=$targets -v mov="$mov" -v msize="$moving" '
  FNR == 1 { R = (FNR == NR ? 0 : 1); next }
  {
    k = FNR - 2; s = k % S; v = int(k / S); if (v + 1 > V[R]) V[R] = v + 1
    e[R, s, v] = $8; p[R, s, v] = $11; sh[R, s, v] = $17; fl[R, v] = $16; view[R, v] = $3; gsub(/"/, "", view[R, v])
    if (R == 0) ms[s, v] = $14
    noise[R, v] = $19
  }
  END {
    n = split(names, nm, "|"); split(idx, ix, " "); split(specs, sp, "|"); b = nm[1]
    # T[s]: the time over the baseline the targets judge: moving (gi_time.sh) when measured, else still.
    split(mov, mv, "|")
    for (i = 1; i <= n; i++) label[ix[i]] = sp[i]
    refs = (R == 1 ? 2 : 1); rname[0] = "POV-Ray"; rname[1] = "Cycles"
    for (r = 0; r < refs; r++) {
      for (s = 0; s < S; s++) {
        E[r, s] = SH[r, s] = SN[r, s] = UP[r, s] = DOWN[r, s] = PR[r, s] = 0
        for (v = 0; v < V[r]; v++) {
          E[r, s] += e[r, s, v] / V[r]; if (r == 0) M[s] += ms[s, v] / V[r]
          if (s == 0) continue
          if (sh[r, s, v] != "n/a") { SH[r, s] += sh[r, s, v]; SN[r, s]++ }
          UP[r, s] += e[r, s, v] < e[r, 0, v]; DOWN[r, s] += e[r, s, v] > e[r, 0, v]; PR[r, s] += p[r, s, v] > p[r, 0, v]
        }
        if (SN[r, s]) SH[r, s] /= SN[r, s]
      }
      for (v = 0; v < V[r]; v++) FL[r] += fl[r, v] / V[r]
    }
    printf "%d views; direct-only floor (%s against POV-Ray without radiosity): mean error %.5f", V[0], b, FL[0]
    if (refs == 2) printf "; %d views against Cycles, with 0 bounces: %.5f", V[1], FL[1]
    printf "\n\n%-13s %-40s %8s", "technique", "setting", "ms"
    for (r = 0; r < refs; r++) printf " | %-8s %9s %7s %8s %8s", rname[r], "mean err", "indir.%", "improved", "Pearson+"
    printf " | %6s%s\n", "time x", (mov != "" ? sprintf(" | %8s", "moving x") : "")
    for (i = 1; i <= n; i++) {
      s = ix[i]
      printf "%-13s %-40s %8.2f", nm[i], sp[i], M[s]
      for (r = 0; r < refs; r++)
        if (s == 0) printf " | %-8s %9.5f %7s %8s %8s", "", E[r, s], "", "", ""
        else printf " | %-8s %9.5f %7s %4d/%-3d %4d/%-3d", "", E[r, s], (SN[r, s] ? sprintf("%.1f", SH[r, s]) : "n/a"),
                    UP[r, s], V[r], PR[r, s], V[r]
      printf " | %6.2f", (M[0] > 0 ? M[s] / M[0] : 0)
      if (mov != "") printf " | %8s", (mv[s + 1] != "" ? sprintf("%.2f", mv[s + 1]) : "n/a")
      printf "\n"
    }
    for (s = 0; s < S; s++) T[s] = mov != "" ? (mv[s + 1] != "" ? mv[s + 1] + 0 : 1e9) : (M[0] > 0 ? M[s] / M[0] : 1e9)
    tname = mov != "" ? sprintf(" (moving camera, %s)", msize) : ""
    if (refs == 2) {
      printf "\nCycles references'"'"' noise (mean |difference| of two seeds, share of %s'"'"'s error against them):\n", b
      for (v = 0; v < V[1]; v++) {
        q = e[1, 0, v] > 0 ? 100 * noise[1, v] / e[1, 0, v] : 0
        q = noise[1, v] == "n/a" ? "n/a (no second seed)" : sprintf("%.5f %5.1f%%", noise[1, v], q)
        printf (v % 3 == 2 || v == V[1] - 1 ? "  %-22s %s\n" : "  %-22s %-20s"), view[1, v], q
      }
    }
    if (!targets) exit
    for (i = 1; i <= n; i++) if (nm[i] == "default") d = ix[i]; else if (nm[i] == "ssdo+esm") so = ix[i]; else if (nm[i] == "ssao+esm") sa = ix[i]
    for (i = 1; i <= n; i++) if (nm[i] == "rsm+esm") rs = ix[i]; else if (nm[i] == "vpl+esm") vp = ix[i]; else if (nm[i] == "combined") co = ix[i]; else if (nm[i] == "lpv+esm") lp = ix[i]
    printf "\ntargets:\n"
    for (r = 0; r < refs; r++) {
      printf "  %s  the default removes at least 60%% of %s'"'"'s indirect error against %s (mean over views): %s\n",
             (SN[r, d] && SH[r, d] >= 60 ? "PASS" : "FAIL"), b, rname[r], (SN[r, d] ? sprintf("%.1f%%", SH[r, d]) : "n/a")
      printf "  %s  the default improves every view against %s: %d of %d\n", (UP[r, d] == V[r] ? "PASS" : "FAIL"),
             rname[r], UP[r, d], V[r]
      printf "  %s  the default raises Pearson in every view against %s: %d of %d\n", (PR[r, d] == V[r] ? "PASS" : "FAIL"),
             rname[r], PR[r, d], V[r]
    }
    printf "  %s  the default takes at most 2x %s'"'"'s time%s: %.2fx\n", (T[d] <= 2 ? "PASS" : "FAIL"), b, tname, T[d]
    if (refs == 2) {
      best = -1
      for (s = 1; s < S; s++) if (T[s] <= 3 && SN[1, s] && (best < 0 || SH[1, s] > SH[1, best])) best = s
      printf "  %s  the best technique within 3x %s'"'"'s time%s removes at least 85%% against Cycles: %s\n",
             (best >= 0 && SH[1, best] >= 85 ? "PASS" : "FAIL"), b, tname,
             (best >= 0 ? sprintf("%.1f%% (%s)", SH[1, best], label[best]) : "n/a")
    }
    printf "  %s  ssdo+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
           (DOWN[0, so] == 0 ? "PASS" : "FAIL"), DOWN[0, so], V[0], E[0, 0], E[0, so]
    printf "  %s  ssao+esm at its defaults raises no view'"'"'s error: %d of %d views worse (mean %.5f -> %.5f)\n",
           (DOWN[0, sa] == 0 ? "PASS" : "FAIL"), DOWN[0, sa], V[0], E[0, 0], E[0, sa]
    if (co) {
      printf "  %s  combined (isr+rsm+esm) removes at least 60%% of %s'"'"'s indirect error: %s\n",
             (SN[0, co] && SH[0, co] >= 60 ? "PASS" : "FAIL"), b, (SN[0, co] ? sprintf("%.1f%%", SH[0, co]) : "n/a")
      printf "  %s  combined improves every view: %d of %d\n", (UP[0, co] == V[0] ? "PASS" : "FAIL"), UP[0, co], V[0]
    }
    if (rs) printf "  %s  rsm+esm removes at least 30%%: %s\n", (SN[0, rs] && SH[0, rs] >= 30 ? "PASS" : "FAIL"),
                   (SN[0, rs] ? sprintf("%.1f%%", SH[0, rs]) : "n/a")
    if (vp) printf "  %s  vpl+esm removes at least 30%%: %s\n", (SN[0, vp] && SH[0, vp] >= 30 ? "PASS" : "FAIL"),
                   (SN[0, vp] ? sprintf("%.1f%%", SH[0, vp]) : "n/a")
    if (lp) printf "  %s  lpv+esm removes at least 30%%: %s\n", (SN[0, lp] && SH[0, lp] >= 30 ? "PASS" : "FAIL"),
                   (SN[0, lp] ? sprintf("%.1f%%", SH[0, lp]) : "n/a")
  }' "${csvs[@]}"
  echo
  echo "mean err: seed eq 19, mean over the views; ms: mean time per frame; indir.%: share of ${names[0]}'s"
  echo "indirect error removed, mean over the views; improved: views with a lower error than ${names[0]};"
  echo "Pearson+: views whose Pearson rose; time x: ms over ${names[0]}'s, measured in the same run (POV-Ray's)."
  [ -z "$moving" ] || echo "moving x: the moving camera's frame over ${names[0]}'s at $moving (MOTION=1 tools/gi_time.sh, the reference set's scenes)."
  echo "report: $out/report.md, $out/report.svg$([ ${#csvs[@]} = 2 ] && echo "; against Cycles: $out/cycles/report.md")"
}
