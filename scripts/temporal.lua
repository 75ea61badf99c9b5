-- Temporal reuse for any coarse GI result (seed 004, chapter 3.3;
-- shaders/temporal.frag): reverse reprojection through the previous frame's
-- matrices, the disocclusion test, accumulation restarted by the seed's
-- confidence. The
-- history is two persistent targets a user (say "rsm") declares from
-- OnCreate at its coarse scale, taking turns (a pass cannot read and write
-- one target); the viewer's reload keeps them by name, format and size.
-- The GI pass turns its sampling pattern each frame (rsm.rotate) so the
-- accumulation averages different samples, and skips the pixels that have
-- converged (temporal.skip): on a still camera it then costs the
-- reprojection and the refreshed tiles.
local options = require "options"

local temporal = {}

temporal.defaults = {
  enabled = false,  -- off: every frame stands alone
  frames = 36,      -- a still pixel averages this many frames, then stops, 1..1024 (36: one
                    -- turn of a pattern turning 10 degrees a frame)
  epsilon = 0.02,   -- disocclusion: reprojected depth within this share of the stored one, (0, 1]
  bias = 0.1,       -- the seed's confidence bias, 0..16
  confidence = 0.25, -- a pixel whose confidence falls below this starts again, 0..1 (above
                     -- about 0.5 the noise of a few samples restarts pixels that should not)
  refresh = 32,     -- a converged pixel's 4 x 4 tile takes fresh samples one frame in this many,
                    -- so that a change of its light shows within as many frames, 0..1024 (0: never;
                    -- the seed: one 16 x 16 tile a frame, 1 in 256 at its half of 512 x 512)
}

local rules = {
  enabled = options.boolean,
  frames = options.number(1, 1024),
  epsilon = options.positive(1),
  bias = options.number(0, 16),
  confidence = options.number(0, 1),
  refresh = options.whole(0, 1024),
}

local histories = {} -- user -> { targets = {a, b}, turn = 0, scale = s }

-- Declares the history of `user` at `scale` of the output; from OnCreate.
function temporal.create(user, scale)
  local function history(i)
    return { value = target{ "temporal." .. user .. i, format = "rgba32f", scale = scale },
             depth = target{ "temporal." .. user .. "_depth" .. i, format = "r32f", scale = scale } }
  end
  histories[user] = { scale = scale, turn = 0, targets = { history(0), history(1) } }
end

-- Checked options under `name` (errors point at the caller's caller).
function temporal.check(name, o) return options.check(name, temporal.defaults, o, rules, 3) end

-- The history of `user` at `scale`, checked (errors point at the caller's caller).
local function history_of(user, scale)
  local h = histories[user]
  if not h then error("temporal: call temporal.create(\"" .. user .. "\", scale) from OnCreate", 3) end
  if h.scale ~= scale then
    error(string.format("temporal: the history of %s is at scale %g, the result at %g", user, h.scale, scale), 3)
  end
  return h
end

-- Adds to a GI pass's inputs, defines and params what it needs to skip the
-- pixels whose accumulation has converged (TEMPORAL_SKIP, temporal.glsl):
-- the history temporal.apply will read this frame. Nothing when off. The
-- pass tests each pixel at its coarse depth (temporal.glsl), as the
-- accumulation will.
function temporal.skip(user, inputs, defines, params, o, scale)
  if not o.enabled then return end
  local previous = history_of(user, scale).targets[histories[user].turn + 1]
  inputs.history, inputs.history_depth = previous.value, previous.depth
  defines.TEMPORAL_SKIP = true
  params.frames, params.epsilon, params.refresh = o.frames, o.epsilon, o.refresh
end

-- The accumulated result of `src`, a coarse result at the scale the history
-- was declared with (C: the coarse grid, a copy of the G-buffer with dpt
-- and mat or a view with its depth z, isr.coarse_view), or src itself when
-- off; and the new history (rgb the value, a the frames it holds), nil when
-- off.
function temporal.apply(user, src, C, o, scale)
  if not o.enabled then return src end
  local h = history_of(user, scale)
  local previous, next = h.targets[h.turn + 1], h.targets[2 - h.turn]
  h.turn = 1 - h.turn
  local out = target{ "temporal." .. user, format = "rgba16f", scale = scale }
  pass{ "temporal." .. user, shader = "temporal.frag",
        inputs = { src = src, history = previous.value, history_depth = previous.depth, dpt = C.z or C.dpt,
                   mat = not C.z and C.mat or nil },
        defines = { Z_MASK = C.z ~= nil }, params = { epsilon = o.epsilon, bias = o.bias, frames = o.frames, confidence = o.confidence,
                   refresh = o.refresh },
        fetches = 6, out = { out, next.value, next.depth } }
  return out, next.value
end

return temporal
