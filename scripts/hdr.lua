-- HDR tone mapping with eye adaptation (seed 001 lines 208-291, 1355-1400;
-- seed 003 "Eye adaptation") over any float image:
--   1. hdr.reduceN: the log-average luminance, eq 2.1, by 8x8 reduction
--      passes down to 1x1 (hdr_reduce.frag says why not glGenerateMipmap)
--   2. hdr.adapt: the adapted luminance moves `rate` of the way to the
--      average each frame, in a persistent 1x1 target; a pass cannot read
--      and write one target, so two of them take turns (ping-pong)
--   3. hdr.tonemap: key, exposure bias, Reinhard with white (eq 2.2-2.4);
--      linear display values in [0, 1] (the output stage encodes sRGB)
-- A pipeline calls hdr.create() from OnCreate and hdr.render() from OnRender.
local options = require "options"

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

-- Records tone mapping of `src` (an output-sized float target) with options
-- o (see hdr.defaults). Returns the display-referred target, or src when off.
function hdr.render(src, o)
  o = hdr.check(o, 2)
  if not o.enabled then return src end
  if not adapted then error("hdr: call hdr.create() from OnCreate (it declares the adaptation targets)", 2) end
  local w, h = output_size()
  local level, n = src, 0
  repeat
    w, h, n = (w + BLOCK - 1) // BLOCK, (h + BLOCK - 1) // BLOCK, n + 1
    level = pass{ "hdr.reduce" .. n, shader = "hdr_reduce.frag", inputs = { src = level },
                  params = n == 1 and { delta = o.delta } or nil,
                  defines = { FIRST = n == 1, BLOCK = BLOCK },
                  out = target{ "hdr.reduce" .. n, format = "rg32f", size = { w, h } } }
  until w == 1 and h == 1
  local previous, next = adapted[turn + 1], adapted[2 - turn]
  turn = 1 - turn
  pass{ "hdr.adapt", shader = "hdr_adapt.frag", inputs = { average = level, previous = previous },
        params = { rate = o.rate }, out = next }
  return pass{ "hdr.tonemap", shader = "hdr_tonemap.frag", inputs = { src = src, adapted = next },
               params = { key = o.key, white = o.white, exposure = o.exposure },
               defines = { AUTO_KEY = o.auto_key },
               out = target{ "hdr.tonemap", format = "rgba16f" } }
end

return hdr
