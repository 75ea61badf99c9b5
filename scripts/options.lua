-- Checking an effect's options against its defaults and rules, shared by the
-- effect modules (isr.lua, ssdo.lua, bloom.lua, dof.lua ...), whose tables
-- of defaults and rules are data that reads alike from module to module. Errors name the
-- option ("dof.focus must be ...") and point at the code that called the effect.
local options = {}

local function finite(v) return type(v) == "number" and v == v and v > -math.huge and v < math.huge end

-- What each rule asks, for tools that show an option (the viewer's panel,
-- through options.describe): rule -> { kind = "number" | "whole" | "boolean"
-- | "one_of" | "colour", lo, hi, step, values }. Weak keys: a rule made for
-- one check goes with it.
local about = setmetatable({}, { __mode = "k" })
local function described(what, rule)
  about[rule] = what
  return rule
end

-- Rules: each returns nil when v is fine, else what v must be. A rule gets
-- the option's value v and all the checked options c, for rules that join
-- two options (see ssdo.lua's resolution).
function options.number(lo, hi) -- lo <= v <= hi, finite
  return described({ kind = "number", lo = lo, hi = hi }, function(v)
    if not (finite(v) and v >= lo and v <= hi) then
      return string.format("a finite number in %g..%g", lo, hi)
    end
  end)
end

function options.positive(hi) -- 0 < v <= hi, finite; no bound without hi
  return described({ kind = "number", lo = 0, hi = hi or math.huge }, function(v)
    if not (finite(v) and v > 0 and v <= (hi or math.huge)) then
      return hi and string.format("a number in (0, %g]", hi) or "a positive finite number"
    end
  end)
end

local function whole(v, lo, hi) return finite(v) and v == math.floor(v) and v >= lo and v <= hi end

function options.whole(lo, hi)
  return described({ kind = "whole", lo = lo, hi = hi, step = 1 }, function(v)
    if not whole(v, lo, hi) then return string.format("a whole number in %d..%d", lo, hi) end
  end)
end

function options.multiple(m, lo, hi) -- a whole multiple of m in lo..hi
  local first = math.ceil(lo / m) * m
  return described({ kind = "whole", lo = first, hi = hi, step = m }, function(v)
    if not (whole(v, lo, hi) and v % m == 0) then return string.format("a multiple of %d in %d..%d", m, lo, hi) end
  end)
end

function options.odd(lo, hi)
  return described({ kind = "whole", lo = lo % 2 == 1 and lo or lo + 1, hi = hi, step = 2 }, function(v)
    if not (whole(v, lo, hi) and v % 2 == 1) then return string.format("an odd whole number in %d..%d", lo, hi) end
  end)
end

function options.boolean(v)
  if type(v) ~= "boolean" then return "true or false" end
end
about[options.boolean] = { kind = "boolean" }

function options.one_of(...)
  local list = { ... }
  return described({ kind = "one_of", values = list }, function(v)
    for _, x in ipairs(list) do if v == x then return nil end end
    return "one of " .. table.concat(list, ", ")
  end)
end

-- "r,g,b" or "x" (grey) as a list of 3 numbers, each in 0..hi; nil when it is neither.
function options.rgb(v, hi)
  if type(v) == "number" then v = tostring(v) end
  if type(v) ~= "string" then return nil end
  local c = {}
  for x in (v .. ","):gmatch("([^,]*),") do c[#c + 1] = tonumber(x) end
  if #c == 1 then c[2], c[3] = c[1], c[1] end
  if #c ~= 3 then return nil end
  for i = 1, 3 do
    if not (finite(c[i]) and c[i] >= 0 and c[i] <= hi) then return nil end
  end
  return c
end

-- A colour as text, "r,g,b" or one grey number, each in 0..hi (text, so that --set takes it).
function options.colour(hi)
  return described({ kind = "colour", lo = 0, hi = hi }, function(v)
    if not options.rgb(v, hi) then return '"r,g,b" or one number, each in 0..' .. string.format("%g", hi):gsub("e%+0*", "e") end
  end)
end

-- A copy of `defaults` with the fields of `o` over it, checked by `rules`
-- (field -> a rule, or a list of rules tried in order; a field without one is
-- checked by what it is passed to). `name` prefixes messages; `level` is how
-- many calls up the effect's caller is (1: whoever called check).
function options.check(name, defaults, o, rules, level)
  options.declare(name, rules)
  level = (level or 1) + 1
  o = o or {}
  if type(o) ~= "table" then error(name .. " options must be a table", level) end
  local c = {}
  for k, v in pairs(defaults) do
    if o[k] == nil then c[k] = v else c[k] = o[k] end
  end
  for k in pairs(o) do
    if defaults[k] == nil and k ~= "name" then
      local known = {}
      for d in pairs(defaults) do known[#known + 1] = d end
      table.sort(known)
      error(string.format("%s.%s is not an option (known: %s)", name, tostring(k), table.concat(known, ", ")), level)
    end
  end
  local keys = {}
  for k in pairs(rules) do keys[#keys + 1] = k end
  table.sort(keys) -- the same option is reported first every run
  for _, k in ipairs(keys) do
    local list = type(rules[k]) == "table" and rules[k] or { rules[k] }
    for _, rule in ipairs(list) do
      local want = rule(c[k], c)
      if want then error(string.format("%s.%s must be %s (got %s)", name, k, want, tostring(c[k])), level) end
    end
  end
  return c
end

-- A pipeline's own options: each field of `keys` in `o` checked by its rule
-- in `rules`; the first bad one an error naming it ("ambient must be ...")
-- that points at the caller `level` calls up (1: whoever called fields).
function options.fields(o, rules, keys, level)
  for _, k in ipairs(keys) do
    local want = rules[k](o[k])
    if want then error(string.format("%s must be %s (got %s)", k, want, tostring(o[k])), (level or 1) + 1) end
  end
end

-- A module's check(o, level) (scripts/README.md): o over `defaults`, checked
-- by `rules`; errors point at the caller `level` calls up (1: check's).
function options.checker(name, defaults, rules)
  options.declare(name, rules)
  return function(o, level)
    local c = options.check(name, defaults, o, rules, (level or 1) + 1) -- not a tail call: it keeps its level
    return c
  end
end

-- Rules by the name of the options they check ("dof", "isr.seed"; "" the
-- pipeline's own), for options.describe. check and checker declare theirs;
-- a module whose check runs only when a technique uses it declares at load.
local declared = {}
function options.declare(name, rules) declared[name] = rules end

-- What the rule of option `path` ("isr.temporal.frames") asks (see `about`),
-- or nil when no declared rule describes it. Rules declared under a shorter
-- name serve a table nested under any module ("temporal" for "isr.temporal").
function options.describe(path)
  local table_name, field = path:match("^(.*)%.([^.]+)$")
  if not table_name then table_name, field = "", path end
  while true do
    local rules = declared[table_name]
    local rule = rules and rules[field]
    for _, r in ipairs(type(rule) == "table" and rule or { rule }) do
      if about[r] then return about[r] end
    end
    table_name = not rule and table_name:match("^[^.]+%.(.+)$")
    if not table_name then return nil end
  end
end

-- A deep copy, for putting a module's defaults into a pipeline's Options.
function options.copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = type(v) == "table" and options.copy(v) or v end
  return c
end

return options
