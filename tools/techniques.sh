# The techniques that the main job (tools/dev.sh run) and the fidelity
# benchmark (tools/fidelity.sh) compare, named in this one place. Sourced;
# LIMN names the limn binary. The default technique is not named here: it is
# the first of scripts/pp.lua's Techniques, what `limn capture` renders
# without --tech, so a new default needs no edit here.

LIMN_BASELINE=dl+esm  # direct light with shadows: the references have shadows

# The default technique (the pipeline's first).
limn_default_technique() {
  "$LIMN" capture --list-options | sed -n 's/^techniques: \([^ ]*\).*/\1/p'
}

# An option's default value, empty when the pipeline has no such option.
limn_option_default() {
  "$LIMN" capture --list-options | sed -n 's/^options: //p' | tr ',' '\n' | sed -n "s/^ *$1=//p"
}

# Sweep specs (limn report --sweep). Options stay set from one setting to the
# next in a report, so a spec that depends on isr.mode sets it.
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
