-- Depth of field over the G-buffer's linear depth: the circle of confusion
-- (dof_coc.frag: focus and range, or a thin lens) and a gather blur that
-- keeps a sharp foreground from bleeding onto a blurred background and lets
-- a blurred foreground spread over a sharp one (dof_gather.frag).
local options = require "options"

local dof = {}

dof.defaults = {
  enabled = false,
  mode = "range",       -- "range": focus and range; "lens": thin lens
  focus = 3.5,          -- focus distance from the eye, world units (clamped to near .. far)
  range = 1.0,          -- range: depth distance from the focus to full blur, > 0
  max_radius = 8,       -- largest circle of confusion in pixels, 0..32 (0: sharp)
  samples = 48,         -- gather taps, 1..256
  focal_length = 0.05,  -- lens: world units (0.05: 50 mm when a unit is a metre), > 0
  f_number = 2.8,       -- lens: N, aperture = focal_length / N, > 0
  sensor = 0.024,       -- lens: sensor height, world units, > 0
}

local rules = {
  enabled = options.boolean,
  mode = options.one_of("range", "lens"),
  focus = options.number(0, 1e6),
  range = options.positive(1e6),
  max_radius = options.number(0, 32),
  samples = options.whole(1, 256),
  focal_length = options.positive(100),
  f_number = options.positive(1000),
  sensor = options.positive(100),
}

-- Records depth of field over `src` (output-sized) with the G-buffer G.
-- Returns the blurred image, or src when off.
function dof.render(src, o, G)
  o = options.check("dof", dof.defaults, o, rules, 2)
  if not o.enabled then return src end
  if not (G and G.dpt) then error("dof: needs the G-buffer's depth (G.dpt)", 2) end
  local coc = pass{ "dof.coc", shader = "dof_coc.frag", inputs = { dpt = G.dpt },
                    params = o.mode == "lens"
                      and { focus = o.focus, max_radius = o.max_radius, focal_length = o.focal_length,
                            f_number = o.f_number, sensor = o.sensor }
                      or { focus = o.focus, range = o.range, max_radius = o.max_radius },
                    defines = { LENS = o.mode == "lens" },
                    out = target{ "dof.coc", format = "rg32f" } }
  return pass{ "dof.gather", shader = "dof_gather.frag", inputs = { src = src, coc = coc },
               params = { max_radius = o.max_radius, samples = o.samples },
               out = target{ "dof.gather", format = "rgba16f" } }
end

return dof
