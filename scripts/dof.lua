-- Depth of field over the G-buffer's linear depth: the circle of confusion
-- (dof.glsl: focus and range, or a thin lens) and a gather blur that
-- keeps a sharp foreground from bleeding onto a blurred background and lets
-- a blurred foreground spread over a sharp one (dof_gather.frag).
-- The gather covers, per 8 x 8 tile, only the largest circle reaching it
-- (dof_tiles.frag). At downsample 2 (the default; the seed is silent on how
-- depth of field is computed) it runs at half size a side with half the
-- taps (a quarter gave visibly more noise for little gain), and only the
-- light it moves between pixels comes back to full size, through ISR's
-- depth-aware upsampling, so sharp pixels keep their full-size detail
-- (dof_reduce.frag, which computes the reduced circles from the depth, and
-- dof_composite.frag).
-- Laid out as scripts/README.md's contract says, so modules read alike.
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
  samples = 48,         -- gather taps over max_radius at full size, 1..256
  downsample = 2,       -- gather resolution: 1/1 or 1/2 a side
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
  downsample = options.one_of(1, 2),
  focal_length = options.number(0, 1e30),
  f_number = options.positive(1000),
  sensor = options.number(0, 1e30),
}

dof.check = options.checker("dof", dof.defaults, rules)

-- Records depth of field over `src` (output-sized) with the frame's G-buffer (frame.G).
-- Returns the blurred image, or src when off. With `fold` (post.lua, where
-- tone mapping reads the image and nothing else does) at downsample 2 the
-- composite is not recorded: it returns the composite's parts (dof.parts),
-- and the passes that read them compute it as they read (dof.glsl).
function dof.render(src, o, frame, fold)
  o = dof.check(o, 2)
  local G = frame and frame.G
  if not o.enabled then return src end
  if not (G and G.dpt) then error("dof: needs the G-buffer's depth (frame.G.dpt)", 2) end
  local params = o.mode == "lens"
    and { focus = o.focus, max_radius = o.max_radius, focal_length = o.focal_length, f_number = o.f_number,
          sensor = o.sensor }
    or { focus = o.focus, range = o.range, max_radius = o.max_radius }
  local f = o.downsample
  local image, circles = src, target{ f > 1 and "dof.small_coc" or "dof.coc", format = "rg32f", scale = 1 / f }
  if f > 1 then
    -- The circles of the reduced image straight from the depth (dof_reduce.frag):
    -- a full-size pass and target fewer.
    image = target{ "dof.small", format = "rgba16f", scale = 1 / f }
    pass{ "dof.reduce", shader = "dof_reduce.frag", inputs = { src = src, dpt = G.dpt }, params = params,
          defines = { LENS = o.mode == "lens" }, out = { image, circles } }
  else
    pass{ "dof.coc", shader = "dof_coc.frag", inputs = { dpt = G.dpt }, params = params,
          defines = { LENS = o.mode == "lens" }, out = circles }
  end
  -- The largest circle reaching each 8 x 8 tile: the gather spreads its taps
  -- over that radius, as many as keep the density of `samples` over max_radius.
  local tile, radius = 8, o.max_radius / f
  -- The smallest too: where every circle near a tile is large, the reduced
  -- gather reads its taps from the image at half its size again, a quarter
  -- as many (dof_quarter.frag).
  local tiles = pass{ "dof.tiles", shader = "dof_tiles.frag", inputs = { src = circles }, defines = { TILE = tile },
                      out = target{ "dof.tiles", format = "rg16f", scale = 1 / (tile * f) } }
  tiles = pass{ "dof.dilate", shader = "dof_tiles.frag", inputs = { src = tiles },
                params = { max_radius = radius }, defines = { TILE = tile, DILATE = true },
                out = target{ "dof.dilate", format = "rg16f", scale = 1 / (tile * f) } }
  local quarter = f > 1 and pass{ "dof.quarter", shader = "dof_quarter.frag", inputs = { src = image },
                                  out = target{ "dof.quarter", format = "rgba16f", scale = 1 / (2 * f) } } or nil
  local gathered = pass{ "dof.gather", shader = "dof_gather.frag",
                         inputs = { src = image, coc = f == 1 and circles or nil, tiles = tiles, -- else image.a
                                    quarter = quarter },
                         params = { max_radius = radius, samples = math.max(1, o.samples // f) },
                         defines = { TILE = tile, FOREIGN = f > 1 },
                         out = target{ "dof.gather", format = "rgba16f", scale = 1 / f } }
  if f == 1 then return gathered end
  local composite = { src = src, dpt = G.dpt, foreign = gathered, small_coc = circles }
  if fold then return { composite = composite, small = image } end
  return pass{ "dof.composite", shader = "dof_composite.frag", inputs = composite,
               out = target{ "dof.composite", format = "rgba16f" } }
end

-- The parts of the composite dof.render(..., fold) left unwritten, or nil
-- when img is a target: { composite = dof_composite.frag's inputs (full-size
-- src and dpt, reduced foreign and small_coc), small = the half-size image }.
-- A pass reads the full-size composite with inputs = parts.composite and the
-- define DOF (dof.glsl's dof_composite), or the reduced one with small and
-- foreign (dof_composite_small).
function dof.parts(img)
  return type(img) == "table" and img.composite and img or nil
end

return dof
