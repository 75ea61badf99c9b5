-- Image-space radiosity (seed 000, Listing 3, lines 1303-1331) over the
-- G-buffer of gbuffer.lua:
--   1. coarse CLR, NRM, DPT, MAT (isr_downsample.frag; skipped at coarse 1)
--   2. sender radiance L_X: the coarse albedo (the seed) or its direct light
--   3. the ISR step: indirect light and ambient occlusion (isr.frag, eq 25-26),
--      repeated for more bounces with the last bounce added to L_X
--   4. a separable Gaussian blur of the coarse result that skips background
--      and does not cross depth edges (blur.frag)
--   5. direct light, bilateral upsampling and the composite (isr_light.frag,
--      eq 27-29)
-- Sample pattern: a golden-angle (Vogel) spiral turned per pixel; see isr.frag.
local gbuffer = require "gbuffer"
local options = require "options"
local shadow = require "shadow"

local isr = {}

-- The options a pipeline exposes (pp.lua's Options.isr), with their defaults.
isr.defaults = {
  samples = 48,      -- N samples a pixel, 1..256 (the seed timed 48; 80 after its fig 5.7)
  radius = 0.5,      -- sampling disc radius in world units, > 0
  coarse = 2,        -- coarse factor a side: 1, 2 or 4
  blur = 4,          -- Gaussian taps each side at coarse size, 0..32 (0: no blur)
  k_isr = 0.5,       -- indirect light power k_ISR, 0..1
  k_ssao = 0.5,      -- ambient occlusion power k_SSAO, 0..1
  sender = "albedo", -- L_X: "albedo" (unlit, the seed) or "lit" (direct light)
  bounces = 1,       -- transport steps, 1..4 (1: the seed)
  view = "lit",      -- "lit"; "indirect" (rho L_ISR) or "ao" (accessibility) to inspect
}

local views = { lit = 0, indirect = 1, ao = 2 }

local rules = {
  samples = options.whole(1, 256),
  radius = options.positive(),
  coarse = options.one_of(1, 2, 4),
  blur = options.whole(0, 32),
  k_isr = options.number(0, 1),
  k_ssao = options.number(0, 1),
  sender = options.one_of("albedo", "lit"),
  bounces = options.whole(1, 4),
  view = options.one_of("lit", "indirect", "ao"),
}

-- The coarse G-buffer: G itself at factor 1.
local function coarse_gbuffer(G, f)
  if f == 1 then return G end
  local C = {
    clr = target{ "isr.clr", format = "rgba8", scale = 1 / f },
    nrm = target{ "isr.nrm", format = "rgba16f", scale = 1 / f },
    dpt = target{ "isr.dpt", format = "r32f", scale = 1 / f },
    mat = target{ "isr.mat", format = "rgba8", scale = 1 / f },
  }
  pass{ "isr.downsample", shader = "isr_downsample.frag", inputs = gbuffer.inputs(G),
        defines = { FACTOR = f }, out = { C.clr, C.nrm, C.dpt, C.mat } }
  return C
end

local function coarse_target(name, f)
  return target{ name, format = "rgba16f", scale = 1 / f }
end

-- Records ISR lighting of G with options o (see isr.defaults) and light =
-- { ambient = {r, g, b}, background = {r, g, b}, shadows = atlas or nil }.
-- Returns the lit target.
function isr.render(G, o, light)
  o = options.check("isr", isr.defaults, o, rules, 2)
  local f = o.coarse
  local C = coarse_gbuffer(G, f)
  local sender = C.clr
  if o.sender == "lit" then
    local inputs, defines = shadow.bind(light.shadows, gbuffer.inputs(C), {})
    sender = pass{ "isr.sender", shader = "direct.frag", inputs = inputs, defines = defines,
                   params = { ambient = light.ambient, background = light.background },
                   out = coarse_target("isr.sender", f) }
  end
  local E
  for b = 1, o.bounces do
    local inputs = gbuffer.inputs(C)
    inputs.sender, inputs.previous = sender, E
    E = pass{ b == 1 and "isr.transport" or "isr.transport" .. b, shader = "isr.frag",
              inputs = inputs, params = { samples = o.samples, radius = o.radius },
              fetches = 4 + o.samples * (E and 6 or 5), -- at most: G-buffer and sender (and bounce) a sample
              defines = { BOUNCE = E ~= nil }, out = coarse_target("isr.e" .. b, f) }
  end
  if o.blur > 0 then
    for _, axis in ipairs{ { "x", { 1, 0 } }, { "y", { 0, 1 } } } do
      E = pass{ "isr.blur_" .. axis[1], shader = "blur.frag",
                inputs = { src = E, mask = C.mat, depth = C.dpt },
                params = { axis = axis[2], radius = o.blur }, defines = { MASK = true, DEPTH = true },
                out = coarse_target("isr.blur_" .. axis[1], f) }
    end
  end
  local inputs, defines = shadow.bind(light.shadows, { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat,
                                                       isr = E, coarse_dpt = C.dpt, coarse_mat = C.mat }, {})
  return pass{ "isr.light", shader = "isr_light.frag", inputs = inputs, defines = defines,
               params = { ambient = light.ambient, background = light.background,
                          k_isr = o.k_isr, k_ssao = o.k_ssao, view = views[o.view] },
               out = target{ "lit", format = "rgba16f" } }
end

return isr
