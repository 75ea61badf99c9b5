-- Temporal reuse for any coarse GI result (seed 004, chapter 3.3;
-- shaders/temporal.glsl): reverse reprojection through the previous frame's
-- matrices, the disocclusion test, accumulation restarted by the seed's
-- confidence, all inside the GI pass (rsm.frag's TEMPORAL): the pass that
-- computes a pixel's value also blends it with its history and writes the
-- next, and skips the pixels that have converged, so a still camera's frame
-- costs the reprojection and the refreshed tiles. The history is two
-- persistent targets a user (say "rsm") declares from OnCreate at its
-- coarse scale, taking turns (a pass cannot read and write one target);
-- the viewer's reload keeps them by name, format and size. The GI pass
-- turns its sampling pattern each frame (rsm.rotate) so the accumulation
-- averages different samples.
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

-- Adds to a GI pass's inputs, defines and params the history of `user`
-- at `scale` (TEMPORAL, temporal.glsl: the pass accumulates, and skips the
-- pixels that have converged), and returns the targets the pass writes this
-- frame's history to, its outputs after its result and depth: { value,
-- depth }; value (a: the frames each pixel holds) is what isr.blur's age
-- reads. Nothing when off.
function temporal.bind(user, inputs, defines, params, o, scale)
  if not o.enabled then return nil end
  local h = history_of(user, scale)
  local previous, next = h.targets[h.turn + 1], h.targets[2 - h.turn]
  h.turn = 1 - h.turn
  inputs.history, inputs.history_depth = previous.value, previous.depth
  defines.TEMPORAL = true
  params.frames, params.epsilon, params.refresh = o.frames, o.epsilon, o.refresh
  params.bias, params.confidence = o.bias, o.confidence
  return next
end

return temporal
