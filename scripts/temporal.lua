-- Temporal reuse for any coarse GI result (seed 004, chapter 3.3;
-- shaders/temporal.glsl): reverse reprojection through the previous frame's
-- matrices, the disocclusion test, accumulation restarted by the seed's
-- confidence, all inside the GI pass (rsm.frag's and isr_march.frag's
-- TEMPORAL): the pass that computes a pixel's value also blends it with its
-- history and writes the next, and skips the pixels that have converged, so
-- a still camera's frame costs the reprojection and the refreshed tiles. The
-- history is two pairs of persistent targets a user (say "rsm") declares
-- from OnCreate at its coarse scales, taking turns (a pass cannot read and
-- write one target): the value (rgba, all four channels accumulated) and the
-- state (r: view depth, 0 none; g: the frames it holds); the viewer's reload
-- keeps them by name, format and size. The GI pass turns its sampling
-- pattern each frame (rsm.rotate, ISR's next rays of its sequence) so the
-- accumulation averages different samples, or only while the view moves
-- (the `turn` option; temporal.glsl's temporal_turn).
-- Laid out as scripts/README.md's contract says, so modules read alike.
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
  moving = 4,       -- while the camera or the world moves, a view-dependent result's history (ISR's, SSDO's: their
                    -- light at a point depends on what the screen shows) holds at most this many
                    -- frames, and no pixel counts as converged, 0..1024 (0: as a still camera, the
                    -- old view's light kept until a refresh; RSM's light does not depend on the view).
                    -- After a 12-frame slide (test_rsm) ISR's frame lay 0.82%, 1.18%, 1.61% and 1.91%
                    -- of the image's mean from a still camera's at 2, 4, 8 and 16, 2.44% at 0; 4
                    -- keeps the moving image's noise near a 4-frame average
  velocity = true,  -- reproject a surface that moved on its own (a node, a deformed mesh) along the
                    -- G-buffer's velocity target, to its depth then (false: through the previous
                    -- camera alone, as if the world stood still)
  turn = "always",  -- "always": the sampling pattern turns every frame, so that a still view's history
                    -- averages ever more samples (less noise; each frame differs from the last by that
                    -- noise until it converges); "moving": only while the view moves (a still view keeps
                    -- the pattern reuse off takes: its image is reuse off's, and a change of the world shows
                    -- at once; the history then only saves work). RSM's light does not depend on the view:
                    -- "moving" turns it while anything moves. isr.temporal's default is "moving" (the door
                    -- sequence, docs/motion.md)
  narrow = 0.25,    -- the GI blur's reach for a pixel whose history holds n frames: blur / n^narrow,
                    -- 0..1 (0: the full blur at any age; 1/4: a converged pixel of 36 frames keeps
                    -- 2/5 of it, less blur where the noise averaged out). isr.temporal's is 0 (the door
                    -- sequence, docs/motion.md: the narrowing blur changed the image each frame as
                    -- the history grew, flicker)
  clamp = 0,        -- neighbourhood clamping: the reprojected history's luminance is held within
                    -- mean +- clamp standard deviations of the log luminance of this frame's fresh
                    -- estimates in the pixel's 3 x 3 neighbourhood (temporal_clamp.frag), so that after
                    -- a change of light it cannot lag behind what the frame sees by more than the noise,
                    -- 0..16 (0: off; ISR's and RSM's histories, RSM's default 6; SSDO's has none:
                    -- docs/motion.md "Clamping")
  skip = true,      -- a settled frame (the world and settings unchanged for `frames` frames: every
                    -- pixel converged) keeps the last result and runs none of the GI passes (ISR's,
                    -- RSM's, SSDO's; false: they run, each pixel keeping its history)
}

local rules = {
  enabled = options.boolean,
  frames = options.number(1, 1024),
  epsilon = options.positive(1),
  bias = options.number(0, 16),
  confidence = options.number(0, 1),
  refresh = options.whole(0, 1024),
  moving = options.number(0, 1024),
  turn = options.one_of("always", "moving"),
  narrow = options.number(0, 1),
  clamp = options.number(0, 16),
  skip = options.boolean,
  velocity = options.boolean,
}
options.declare("temporal", rules) -- serves every module's <module>.temporal (options.describe)

local velocity = nil -- this frame's G-buffer velocity target (temporal.velocity), or nil
local histories = {} -- user -> { view = bool, at = { [coarse factor] = { targets = {a, b}, turn = 0, kept = } } }
local settings, restart = nil, false -- a copy of the last frame's settings (temporal.begin), and whether
                                     -- every history starts again this frame (they, or the light, changed)
local quiet = 0 -- frames in a row before this one with the same world and settings
local relighting = 0 -- frames in a row before this one whose light changed (still_frames("light") 0)

-- Do two values hold the same content (tables compared key by key)?
-- Walked each frame instead of a text key: building and sorting one took
-- about 0.18 ms of the frame's CPU time, as much as the rest of OnRender.
local function same(a, b)
  if type(a) ~= "table" or type(b) ~= "table" then return a == b end
  for k, v in pairs(a) do
    if not same(v, b[k]) then return false end
  end
  for k in pairs(b) do
    if a[k] == nil then return false end
  end
  return true
end

local function copy(v)
  if type(v) ~= "table" then return v end
  local t = {}
  for k, x in pairs(v) do t[k] = copy(x) end
  return t
end

-- Starts a frame, from OnRender before any temporal.bind: `settings_now`
-- is what the GI results depend on besides the scene and the camera (the
-- technique's name and the options of its passes; any value, tables
-- compared by content). When it differs from the last frame's, every
-- history starts again this frame: a history is the same computation's
-- result, and the confidence test would keep one made under other
-- settings wherever the two differ by less than its threshold (a report's
-- next setting, the viewer's next technique). A pipeline's first frame
-- keeps them: the viewer's reload keeps the histories on purpose.
-- So does a step of the light (a light's colour, power, position or cone,
-- a material's emission: still_frames("light"); the sky, ambient and
-- background are settings): a running mean would keep the old light as
-- a share of held / (held + new frames), and a converged pixel keeps it
-- all (its confidence sees a x4 step of faint bounce light as noise), so
-- the histories start again where the light changes after standing still,
-- and again where it stands still after changing for two frames or more
-- (the history then holds the light of the change's last frames). While it
-- keeps changing, every history is capped at `moving` frames instead
-- (world_moved), so that a light in constant motion keeps its reuse.
function temporal.begin(settings_now)
  restart = settings ~= nil and not same(settings_now, settings)
  if restart or not settings then settings = copy(settings_now) end
  local relit = still_frames("light") == 0
  restart = restart or (relit and relighting == 0) or (not relit and relighting >= 2)
  relighting = relit and relighting + 1 or 0
  quiet = (restart or still_frames() == 0) and 0 or quiet + 1
end

-- This frame's G-buffer velocity target (gbuffer.targets' vel), or nil: with
-- it, a history reprojects each pixel along its surface's own motion (a
-- moving object keeps its history and leaves none behind); without, through
-- the previous camera alone, as if the world stood still.
function temporal.velocity(vel) velocity = vel end

-- May a user keep last frame's result instead of running its passes? When
-- the world and the settings have stayed the same for `frames` frames in a
-- row (still_frames, temporal.begin), every pixel that kept its history
-- holds `frames` frames: converged, it takes no samples and its value
-- stays as it is, and a refreshed tile finds no change to see (nothing
-- changed), so the passes would give the same result again (a pixel whose
-- noise restarted it since keeps the value it has). o: the user's checked
-- options. A settled frame shows results pre-exposed as they were made, so
-- it keeps the last frame's pre-exposure (keep_exposure()): the meter reads
-- a frame late, and after a change of light it may move the exposure on a
-- settled frame, under results it would not rescale (a sun 1e4 times
-- brighter: rsm+esm's settled frames 98 times too bright).
function temporal.settled(o)
  local settled = o.enabled and o.skip and quiet >= o.frames
  if settled then keep_exposure() end
  return settled
end

-- Declares the history of `user` at 1 / f of the output for each coarse
-- factor f of `factors` (a number or a list); from OnCreate. Only the
-- factor a frame uses is made: a persistent target no pass reads or writes
-- has no texture. how (optional): { view = the result depends on the view
-- (a screen-space gather), so a moving camera caps its history (the
-- `moving` option); keep = the user's final result and its grid's depth are
-- kept too (temporal.kept), so that a settled frame can skip its passes;
-- keep = "output": a full-size result instead (kept.value at scale 1, no
-- z: SSDO keeps its composite); clamp = the user's accumulating pass writes
-- TEMPORAL_CLAMP's `fresh` and calls temporal.clamp (the `clamp` option) }.
function temporal.create(user, factors, how)
  if type(factors) == "number" then factors = { factors } end
  how = how or {}
  histories[user] = { view = how.view == true, clamp = how.clamp == true, at = {} }
  for _, f in ipairs(factors) do
    local name = string.format("temporal.%s%d.", user, f)
    local function history(i)
      return { value = target{ name .. "value" .. i, format = "rgba32f", scale = 1 / f },
               state = target{ name .. "state" .. i, format = "rg32f", scale = 1 / f } }
    end
    local kept
    if how.keep == "output" then
      kept = { value = target{ name .. "kept", format = "rgba16f" } }
    elseif how.keep then
      kept = { value = target{ name .. "kept", format = "rgba16f", scale = 1 / f },
               z = target{ name .. "z", format = "r32f", scale = 1 / f } }
    end
    histories[user].at[f] = { turn = 0, targets = { history(0), history(1) }, kept = kept }
  end
end

-- Checked options under `name` (errors point at the caller's caller).
function temporal.check(name, o) return options.check(name, temporal.defaults, o, rules, 3) end

-- The history of `user` at coarse factor f, checked (errors point at the caller's caller).
local function history_of(user, f)
  local all = histories[user]
  if not all then error("temporal: call temporal.create(\"" .. user .. "\", factors) from OnCreate", 3) end
  local h = all.at[f]
  if not h then
    local have = {}
    for k in pairs(all.at) do have[#have + 1] = k end
    table.sort(have)
    error(string.format("temporal: %s has a history at coarse %s, not at coarse %d", user,
                        table.concat(have, ", "), f), 3)
  end
  return h
end

-- The targets `user` (created with keep) writes its final result and its
-- grid's depth to at coarse factor f, where a settled frame reads them:
-- { value = rgba16f, z = r32f }, persistent.
function temporal.kept(user, f) return history_of(user, f).kept end

-- Adds to a GI pass's inputs, defines and params the history of `user`
-- at coarse factor f (TEMPORAL, temporal.glsl: the pass accumulates, and
-- skips the pixels that have converged), and returns the targets this
-- frame's history goes to: { value, state }; state (g: the frames each
-- pixel holds) is what isr.blur's age reads. Nothing when off. A result
-- made in several passes gives each of them these inputs (so all agree on
-- which pixels have converged) and writes the next history from its last.
-- gather_turns: another gather in the pass turns its pattern every frame
-- whatever o.turn says (isr+rsm+esm's RSM), so the history averages it.
-- With o.clamp the pass that accumulates also gets TEMPORAL_CLAMP and writes
-- `fresh` after value and state (its outputs NEXT, NEXT + 1, NEXT + 2), its
-- value going to a frame target that temporal.clamp then clamps into the
-- history.
function temporal.bind(user, inputs, defines, params, o, f, gather_turns)
  if not o.enabled then return nil end
  local h = history_of(user, f)
  local previous, next = h.targets[h.turn + 1], h.targets[2 - h.turn]
  h.turn = 1 - h.turn
  inputs.history, inputs.history_state = previous.value, previous.state
  defines.TEMPORAL = true
  params.frames, params.epsilon, params.refresh = o.frames, o.epsilon, o.refresh
  params.bias, params.confidence, params.restart = o.bias, o.confidence, restart and 1 or 0
  params.moving, params.view_dependent = o.moving, histories[user].view and 1 or 0
  -- The world changed since the last frame: for a view-dependent result anything, camera included; for
  -- another (RSM's light, seen from the lights) the scene alone, so that a moving camera keeps its history
  -- and a light or caster moving under a moving camera still caps it.
  params.world_moved = (histories[user].view and still_frames() or still_frames("scene")) == 0 and 1 or 0
  params.turn = (o.turn == "always" or not histories[user].view and still_frames() == 0) and 1 or 0
  params.gather_turns = gather_turns and 1 or 0
  if velocity and o.velocity then inputs.velocity, defines.VELOCITY = velocity, true end
  if o.clamp > 0 and not histories[user].clamp then
    error(string.format("%s.temporal.clamp: %s's history has no clamping (0, or leave it out)", user, user), 3)
  end
  if o.clamp > 0 then
    local name = string.format("temporal.%s%d.", user, f)
    return { value = target{ name .. "raw", format = "rgba32f", scale = 1 / f }, state = next.state,
             fresh = target{ name .. "fresh", format = "rgba32f", scale = 1 / f }, clamped = next.value,
             k = o.clamp }
  end
  return next
end

-- After the pass that accumulated `next` (temporal.bind's, with
-- TEMPORAL_CLAMP where next.fresh is set): pass "<user>.clamp" holds each
-- pixel's history within its fresh neighbourhood (temporal_clamp.frag) and
-- writes the result to E (the pass's own E, written again) and to the
-- history. Returns E. Nothing without clamping.
function temporal.clamp(user, next, E)
  if not (next and next.fresh) then return E end
  pass{ user .. ".clamp", shader = "temporal_clamp.frag", inputs = { raw = next.value, fresh = next.fresh },
        params = { k = next.k }, out = { E, next.clamped }, fetches = 11 }
  return E
end

return temporal
