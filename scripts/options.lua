-- Checking an effect's options against its defaults and rules, shared by the
-- effect modules (isr.lua, ssdo.lua, bloom.lua, dof.lua ...). Errors name the
-- option ("dof.focus must be ...") and point at the code that called the effect.
local options = {}

local function finite(v) return type(v) == "number" and v == v and v > -math.huge and v < math.huge end

-- Rules: each returns nil when v is fine, else what v must be. A rule gets
-- the option's value v and all the checked options c, for rules that join
-- two options (see ssdo.lua's resolution).
function options.number(lo, hi) -- lo <= v <= hi, finite
  return function(v)
    if not (finite(v) and v >= lo and v <= hi) then
      return string.format("a finite number in %g..%g", lo, hi)
    end
  end
end

function options.positive(hi) -- 0 < v <= hi, finite; no bound without hi
  return function(v)
    if not (finite(v) and v > 0 and v <= (hi or math.huge)) then
      return hi and string.format("a number in (0, %g]", hi) or "a positive finite number"
    end
  end
end

local function whole(v, lo, hi) return finite(v) and v == math.floor(v) and v >= lo and v <= hi end

function options.whole(lo, hi)
  return function(v)
    if not whole(v, lo, hi) then return string.format("a whole number in %d..%d", lo, hi) end
  end
end

function options.multiple(m, lo, hi) -- a whole multiple of m in lo..hi
  return function(v)
    if not (whole(v, lo, hi) and v % m == 0) then return string.format("a multiple of %d in %d..%d", m, lo, hi) end
  end
end

function options.odd(lo, hi)
  return function(v)
    if not (whole(v, lo, hi) and v % 2 == 1) then return string.format("an odd whole number in %d..%d", lo, hi) end
  end
end

function options.boolean(v)
  if type(v) ~= "boolean" then return "true or false" end
end

function options.one_of(...)
  local list = { ... }
  return function(v)
    for _, x in ipairs(list) do if v == x then return nil end end
    return "one of " .. table.concat(list, ", ")
  end
end

-- A copy of `defaults` with the fields of `o` over it, checked by `rules`
-- (field -> a rule, or a list of rules tried in order; a field without one is
-- checked by what it is passed to). `name` prefixes messages; `level` is how
-- many calls up the effect's caller is (1: whoever called check).
function options.check(name, defaults, o, rules, level)
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

-- A module's check(o, level) (scripts/README.md): o over `defaults`, checked
-- by `rules`; errors point at the caller `level` calls up (1: check's).
function options.checker(name, defaults, rules)
  return function(o, level)
    local c = options.check(name, defaults, o, rules, (level or 1) + 1) -- not a tail call: it keeps its level
    return c
  end
end

-- A deep copy, for putting a module's defaults into a pipeline's Options.
function options.copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = type(v) == "table" and options.copy(v) or v end
  return c
end

return options
