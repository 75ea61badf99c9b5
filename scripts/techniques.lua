-- Techniques as rows (pp.lua's): techniques.add{ "name", field = value, ... }
-- checks a row and adds it to the pipeline's Techniques, which the engine
-- reads (the name, the viewer's key) and the pipeline builds frames from.
-- A row's fields:
--   [1]        the technique's name
--   lighting   the module that lights the frame over its direct light (ambient 0); none: the
--              direct pass alone, the ambient term included
--   shadows    shadow maps for the lights (shadow.technique picks their filter)
--   offscreen  the module that adds the light of senders off screen, from the reflective
--              shadow maps the shadow pass then writes (its options size them)
--   joins      how that light joins: "direct" (default: the direct pass upsamples and adds
--              it), "march" (the lighting module's first march gathers it) or "lit" (the
--              module's own full-size pass lights the frame in place of the direct pass)
--   split      senders the camera sees are left to `lighting`: each counted once
--              (docs/gi-combined.md)
--   temporal   the module whose temporal reuse reads the G-buffer's velocity
--   key        the viewer's key: F2-F5 or F10
-- Each module a row names joins the pipeline's Options under its name, with
-- its defaults, the first time a row names it.
local options = require "options"

local techniques = {
  modules = {}, -- name -> module, for every module a row names
  order = {},   -- their names, in the order rows first name them
}

local fields = { lighting = "module", offscreen = "module", temporal = "module", shadows = "boolean",
                 split = "boolean", joins = { direct = true, march = true, lit = true },
                 key = { F2 = true, F3 = true, F4 = true, F5 = true, F10 = true } }
local rows, keys = {}, {}

-- The row of technique `name` (nil for none).
function techniques.row(name) return rows[name] end

-- Adds `row` to the global Techniques (made when missing). A row with an
-- unknown field or value, a module that does not load or a name or key
-- another row has is refused, the error naming the row and pointing at it.
function techniques.add(row)
  local function refuse(why) error(string.format("technique %s: %s", tostring(row[1]), why), 3) end
  if type(row[1]) ~= "string" or rows[row[1]] then refuse("needs a name of its own (first entry)") end
  for k, v in pairs(row) do
    local kind = fields[k]
    if k ~= 1 and not kind then
      refuse(string.format("'%s' is not a field of a row (lighting, shadows, offscreen, joins, split, temporal, key)",
                           tostring(k)))
    end
    if type(kind) == "table" and not kind[v] then refuse(string.format("%s cannot be '%s'", k, tostring(v))) end
    if kind == "boolean" and type(v) ~= "boolean" then refuse(k .. " must be true or false") end
    if k == "key" and keys[v] then refuse(string.format("key %s is %s's", v, keys[v])) end
    if kind == "module" and not techniques.modules[v] then
      local ok, m = pcall(require, v)
      if not ok then refuse(string.format("%s: no module %s (%s)", k, tostring(v), tostring(m))) end
      if type(m) ~= "table" or type(m.defaults) ~= "table" then
        refuse(string.format("%s: %s is not an effect module (no defaults: scripts/README.md)", k, v))
      end
      techniques.modules[v], techniques.order[#techniques.order + 1] = m, v
      Options = Options or {}
      Options[v] = Options[v] or options.copy(m.defaults)
    end
  end
  if row.temporal and row.temporal ~= row.lighting and row.temporal ~= row.offscreen then
    refuse("temporal must be its lighting or offscreen module")
  end
  if (row.joins or row.split) and not row.offscreen then refuse("joins and split go with offscreen") end
  if row.joins == "march" and not row.lighting then refuse('joins = "march" needs a lighting module') end
  -- What the pipeline calls of each (scripts/README.md's contract).
  local need = { lighting = { "render" }, offscreen = { "check", row.joins == "march" and "march" or "render" } }
  for _, k in ipairs{ "lighting", "offscreen" } do
    for _, f in ipairs(row[k] and need[k] or {}) do
      local m = techniques.modules[row[k]]
      if type(m[f]) ~= "function" then refuse(string.format("%s: %s has no %s", k, row[k], f)) end
    end
  end
  if row.key then keys[row.key] = row[1] end
  Techniques = Techniques or {}
  rows[row[1]], Techniques[#Techniques + 1] = row, row
  return row
end

-- Declares the persistent targets of every module a row names (their
-- create(), scripts/README.md): the pipeline's OnCreate calls it.
function techniques.create()
  for _, name in ipairs(techniques.order) do
    if techniques.modules[name].create then techniques.modules[name].create() end
  end
end

-- `list` with the options `tech` holds for each module a row names added:
-- with the pipeline's own, what the GI histories depend on (temporal.begin).
function techniques.settings(tech, list)
  for _, name in ipairs(techniques.order) do list[#list + 1] = tech[name] end
  return list
end

-- Does the frame of `row` with options `tech` read the G-buffer's velocity
-- (motion blur while things move, or the row's temporal reuse while the
-- scene changes)? A frame that does not declares none. Temporal reuse reads
-- it only for surfaces that moved on their own (a = 2, temporal.glsl); in a
-- frame whose scene is the last one's (still_frames("scene") > 0: no node or
-- mesh moved) there are none, and every pixel reprojects through the camera
-- alone, to the bit as with the target, which costs the G-buffer pass a
-- full-size output (isr+rsm+esm's moving frame at 256 x 192: docs/gi-combined.md).
function techniques.reads_velocity(tech, row)
  local function on(t) return type(t) == "table" and t.enabled == true end
  local gi = row.temporal and tech[row.temporal]
  return (on(tech.motion_blur) and still_frames() == 0) or
         (gi ~= nil and on(gi.temporal) and gi.temporal.velocity ~= false and still_frames("scene") == 0)
end

return techniques
