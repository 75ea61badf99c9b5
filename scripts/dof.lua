-- Depth of field over the G-buffer's linear depth: the circle of confusion
-- (dof_coc.frag: focus and range, or a thin lens) and a gather blur that
-- keeps a sharp foreground from bleeding onto a blurred background and lets
-- a blurred foreground spread over a sharp one (dof_gather.frag).
local options = require "options"

local dof = {}

dof.defaults = {
  enabled = false,
  -- Lengths are world units when set; 0 (the default) makes each relative to
  -- the view, so the same image comes out in any unit.
  mode = "range",       -- "range": focus and range; "lens": thin lens
  focus = 0,            -- focus distance from the eye (clamped to near .. far);
                        -- 0: the depth at the image's centre (autofocus)
  range = 0,            -- range: depth distance from the focus to full blur; 0: focus / 3
  max_radius = 8,       -- largest circle of confusion in pixels, 0..32 (0: sharp)
  samples = 48,         -- gather taps, 1..256
  focal_length = 0,     -- lens: 0: focus / 70 (a 50 mm lens focused at 3.5 m)
  f_number = 2.8,       -- lens: N, aperture = focal_length / N, > 0
  sensor = 0,           -- lens: sensor height; 0: what gives the camera's field
                        -- of view with that focal length (focused at infinity)
}

local rules = {
  enabled = options.boolean,
  mode = options.one_of("range", "lens"),
  focus = options.number(0, 1e30),
  range = options.number(0, 1e30),
  max_radius = options.number(0, 32),
  samples = options.whole(1, 256),
  focal_length = options.number(0, 1e30),
  f_number = options.positive(1000),
  sensor = options.number(0, 1e30),
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
