-- Motion blur (motion_blur.frag): each pixel blurred along the screen motion
-- near it, from the G-buffer's velocity target (G.vel: camera, node and
-- deformation motion; pp.lua declares it when motion blur is on), else the
-- camera's alone (the previous frame's view-projection), with depth-aware
-- weights (a moving object smears over what lies behind it, not over what
-- lies in front). A still frame is left as it is, and records no pass after
-- the first. Its checks open as dof.lua's, alike: both read the G-buffer's
-- depth.
local options = require "options"

local motion_blur = {}

motion_blur.defaults = {
  enabled = false,
  strength = 0.5,   -- shutter: fraction of the frame's motion blurred, 0..4
  max_length = 32,  -- longest streak in pixels, 0..256
  samples = 12,     -- reads along the motion, 1..64
}

local rules = {
  enabled = options.boolean,
  strength = options.number(0, 4),
  max_length = options.number(0, 256),
  samples = options.whole(1, 64),
}

-- The side of the tiles whose longest streak a pixel blurs along (found on a
-- grid of 4-pixel tiles first, then of these from it): half the
-- longest streak or more (a streak centred on a pixel reaches half its length
-- each way, and the 3 x 3 tiles around a pixel reach a tile each way), a
-- power of two from 8 to 64 (streaks past 128 pixels reach only as far).
local function tile_side(max_length)
  local t = 8
  while t < max_length / 2 and t < 64 do t = t * 2 end
  return t
end

motion_blur.check = options.checker("motion_blur", motion_blur.defaults, rules)

-- Records motion blur of `src` (output-sized) using the frame's G-buffer
-- (frame.G): its dpt, and its vel when it has one. Returns src when off.
function motion_blur.render(src, o, frame)
  o = motion_blur.check(o, 2)
  local G = frame and frame.G
  if not o.enabled then return src end
  if not (G and G.dpt) then error("motion_blur: needs the G-buffer's depth (frame.G.dpt)", 2) end
  -- Nothing moved since the last frame (the renderer's world hash holds the
  -- camera, the nodes and the deformations): no pixel would change.
  if still_frames() > 0 then return src end
  local inputs, defines = { dpt = G.dpt }, {}
  if G.vel then inputs.vel, defines.VELOCITY = G.vel, true end
  local t = tile_side(o.max_length)
  local params = { strength = o.strength, max_length = o.max_length, samples = o.samples, tile = t }
  local function with(extra, more)
    local d, i = { [extra] = true }, {}
    for k, v in pairs(defines) do d[k] = v end
    for k, v in pairs(inputs) do i[k] = v end
    for k, v in pairs(more or {}) do i[k] = v end
    return d, i
  end
  local d, i = with("TILES")
  local fine = pass{ "motion_blur.tiles4", shader = "motion_blur.frag", inputs = i, defines = d,
                     params = { strength = o.strength, max_length = o.max_length, tile = 4 },
                     out = target{ "motion_blur.tiles4", format = "rg16f", scale = 1 / 4 } }
  d, i = with("TILES", { near = fine })
  d.BLOCKS = true
  local tiles = pass{ "motion_blur.tiles", shader = "motion_blur.frag", inputs = i, defines = d,
                      params = { tile = t // 4 },
                      out = target{ "motion_blur.tiles", format = "rg16f", scale = 1 / t } }
  d, i = with("NEIGHBOURS", { near = tiles })
  local near = pass{ "motion_blur.near", shader = "motion_blur.frag", inputs = i, defines = d, params = params,
                     out = target{ "motion_blur.near", format = "rg16f", scale = 1 / t } }
  inputs.src, inputs.near = src, near
  return pass{ "motion_blur", shader = "motion_blur.frag", inputs = inputs, defines = defines, params = params,
               out = target{ "motion_blur", format = "rgba16f" } }
end

return motion_blur
