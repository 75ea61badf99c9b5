-- Bloom (seed 001 lines 1355-1400, 1745-1781): a bright pass with a soft
-- knee at 1/downsample of the size, a separable Gaussian (blur.frag), and
-- the sum with the image, before tone mapping. Half floats throughout, each
-- pass clamping under their largest finite value.
-- Laid out as scripts/README.md's contract says, so modules read alike.
local options = require "options"
local dof = require "dof"

local bloom = {}

bloom.defaults = {
  enabled = false,
  threshold = 1.0,  -- brightness (largest channel) where bloom starts, >= 0
  knee = 0.5,       -- soft transition either side of the threshold, >= 0
  strength = 0.5,   -- how much of the blurred light is added, >= 0
  radius = 4,       -- Gaussian taps each side at the bloom's size, 0..32 (0: no blur)
  downsample = 4,   -- bloom resolution: 1/1, 1/2 or 1/4 a side
}
-- At a quarter a side with 4 taps the Gaussian's sigma is 8 output pixels, as
-- at half with 8 taps, for an eighth of the blur's reads: the Cornell box
-- with hdr, bloom and dof at 512x384 differs by 0.0003 on average (at most
-- 0.037, at the light's hot spot) and the blur took 34 -> 5 ms a frame
-- (llvmpipe, loaded).

local rules = {
  enabled = options.boolean,
  threshold = options.number(0, 1e6),
  knee = options.number(0, 1e6),
  strength = options.number(0, 1e3),
  radius = options.whole(0, 32),
  downsample = options.one_of(1, 2, 4),
}

bloom.check = options.checker("bloom", bloom.defaults, rules)

-- Records bloom's bright pass and blur over `src` (output-sized, or depth of
-- field's unwritten composite: dof.parts). Returns the glow to add, { image =
-- the blurred target, strength = o.strength }, or nil when off. hdr.render
-- adds it as it reads the image (post.lua), so the sum is never written at
-- full size.
function bloom.glow(src, o)
  o = bloom.check(o, 2)
  if not o.enabled then return nil end
  local f = o.downsample
  local function small(name) return target{ name, format = "rgba16f", scale = 1 / f } end
  local parts = dof.parts(src) -- read at the reduced size below full size (bloom_bright.frag)
  local inputs = not parts and { src = src } or f == 1 and parts.composite
                 or { small = parts.small, foreign = parts.composite.foreign }
  local b = pass{ "bloom.bright", shader = "bloom_bright.frag", inputs = inputs,
                  params = { threshold = o.threshold, knee = o.knee }, defines = { FACTOR = f, DOF = parts ~= nil },
                  out = small("bloom.bright") }
  if o.radius > 0 then
    for _, axis in ipairs{ { "x", { 1, 0 } }, { "y", { 0, 1 } } } do
      b = pass{ "bloom.blur_" .. axis[1], shader = "blur.frag", inputs = { src = b },
                params = { axis = axis[2], radius = o.radius }, out = small("bloom.blur_" .. axis[1]) }
    end
  end
  return { image = b, strength = o.strength }
end

-- Records bloom over `src` (output-sized). Returns the sum, or src when off.
function bloom.render(src, o)
  local glow = bloom.glow(src, bloom.check(o, 2)) -- checked here: an error names bloom.render's caller
  if not glow then return src end
  return pass{ "bloom.add", shader = "bloom_add.frag", inputs = { src = src, bloom = glow.image },
               params = { strength = glow.strength }, out = target{ "bloom.add", format = "rgba16f" } }
end

return bloom
