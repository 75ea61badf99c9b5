-- HDR tone mapping with eye adaptation (seed 001 lines 208-291, 1355-1400;
-- seed 003 "Eye adaptation") over any float image:
--   1. hdr.reduceN: the log-average luminance, eq 2.1, by 8x8 reduction
--      passes down to 1x1 (hdr_reduce.frag says why not glGenerateMipmap),
--      the first reading one pixel of each 4x4 (a sixteenth of the reads;
--      the adaptation smooths what a sampled mean varies: on the Cornell box
--      with bloom and dof the tone mapped image moves by 0.0012 on average
--      from one pixel of each 2x2)
--   2. hdr.adapt: the adapted luminance moves `rate` of the way to the
--      average each frame, in a persistent 1x1 target; a pass cannot read
--      and write one target, so two of them take turns (ping-pong); with it
--      the scale key * 2^exposure / adapted (eq 2.2), once a frame
--   3. hdr.tonemap: that scale, Reinhard with white (eq 2.3-2.4); linear
--      display values in [0, 1] (the output stage encodes sRGB); where the
--      frame presents its image, the output stage runs in this pass
--      (fold_output: a full-size image not written and read again); after
--      depth of field at half size (post.lua), it and the meter lay the
--      blur over the image as they read it (dof.render's fold)
-- A pipeline calls hdr.create() from OnCreate and hdr.render() from OnRender.
local options = require "options"
local dof = require "dof"

local hdr = {}

hdr.defaults = {
  enabled = false,
  key = 0.18,        -- a: middle grey of the scaled image (seed: 0.045 .. 0.9)
  auto_key = false,  -- key from the average instead (seed 001 fig 6.17)
  white = 4.0,       -- L_white: smallest scaled luminance shown as white, > 0
  exposure = 0.0,    -- bias in stops (2^exposure), -20 .. 20
  rate = 0.1,        -- adaptation: fraction of the gap closed a frame, (0, 1]; 1 adapts at once
  delta = 1e-4,      -- delta of eq 2.1, against ln(0), > 0
}

local rules = {
  enabled = options.boolean,
  key = options.number(0.001, 1),
  auto_key = options.boolean,
  white = options.positive(1e6),
  exposure = options.number(-20, 20),
  rate = options.positive(1),
  delta = options.positive(1),
}

local BLOCK = 8 -- reduction factor a side: 64 reads a texel, log8 levels
local STEP = 4  -- the first level reads one pixel of each STEP x STEP

local adapted -- the two persistent 1x1 targets, from hdr.create()
local turn = 0

-- Declares the adaptation targets; call from OnCreate.
function hdr.create()
  adapted = {
    target{ "hdr.adapted0", format = "rgba32f", size = { 1, 1 } },
    target{ "hdr.adapted1", format = "rgba32f", size = { 1, 1 } },
  }
end

hdr.check = options.checker("hdr", hdr.defaults, rules)

-- Records tone mapping of `src` (an output-sized float target, or depth of
-- field's unwritten composite: dof.parts) with options o (see hdr.defaults),
-- adding `glow` (bloom.glow's) to the image as its first reduction and the
-- tone mapping read it. Returns the display-referred target, or src when off.
function hdr.render(src, o, _, glow)
  o = hdr.check(o, 2)
  if not o.enabled then return src end
  if not adapted then error("hdr: call hdr.create() from OnCreate (it declares the adaptation targets)", 2) end
  local w, h = output_size()
  -- The inputs and params of a pass that adds the glow, where there is one.
  local function glow_inputs(t)
    t.bloom = glow and glow.image
    return t
  end
  local function glow_params(t)
    t.strength = glow and glow.strength
    return t
  end
  -- Depth of field's composite unwritten: the meter and tone mapping compute
  -- it at the pixels they read (hdr_reduce.frag, hdr_tonemap.frag).
  local parts = dof.parts(src)
  local image = parts and parts.composite or { src = src }
  local level, n = src, 0
  repeat
    local first = n == 0
    -- Computing the composite, the first level is the costly one: one pixel
    -- a texel, so that its pass has tiles enough for llvmpipe's threads.
    local block = first and parts and 1 or BLOCK
    local f = block * (first and STEP or 1)
    w, h, n = (w + f - 1) // f, (h + f - 1) // f, n + 1
    level = pass{ "hdr.reduce" .. n, shader = "hdr_reduce.frag",
                  inputs = first and glow_inputs(options.copy(image)) or { src = level },
                  params = first and glow_params{ delta = o.delta } or nil,
                  defines = { FIRST = first, BLOCK = block, STEP = first and STEP or 1, BLOOM = first and glow ~= nil,
                              DOF = first and parts ~= nil },
                  out = target{ "hdr.reduce" .. n, format = "rg32f", size = { w, h } } }
  until w == 1 and h == 1
  local previous, next = adapted[turn + 1], adapted[2 - turn]
  turn = 1 - turn
  pass{ "hdr.adapt", shader = "hdr_adapt.frag", inputs = { average = level, previous = previous },
        params = { rate = o.rate, key = o.key, exposure = o.exposure }, defines = { AUTO_KEY = o.auto_key },
        out = next }
  local inputs = glow_inputs(options.copy(image))
  inputs.adapted = next
  return pass{ "hdr.tonemap", shader = "hdr_tonemap.frag", inputs = inputs,
               params = glow_params{ white = o.white }, defines = { BLOOM = glow ~= nil, DOF = parts ~= nil },
               out = target{ "hdr.tonemap", format = "rgba16f" }, fold_output = true }
end

return hdr
