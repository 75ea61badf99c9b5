-- Checking an effect's options against its defaults and rules, shared by the
-- effect modules (bloom.lua, dof.lua, hdr.lua ...). Errors name the option
-- ("dof.focus must be ...") and point at the code that called the effect.
local options = {}

local function finite(v) return type(v) == "number" and v == v and v > -math.huge and v < math.huge end

-- Rules: each returns nil when v is fine, else what v must be.
function options.number(lo, hi) -- lo <= v <= hi, finite
  return function(v)
    if not (finite(v) and v >= lo and v <= hi) then
      return string.format("a finite number in %g..%g", lo, hi)
    end
  end
end

function options.positive(hi) -- 0 < v <= hi
  hi = hi or 1e30
  return function(v)
    if not (finite(v) and v > 0 and v <= hi) then return string.format("a number in (0, %g]", hi) end
  end
end

function options.whole(lo, hi)
  return function(v)
    if not (finite(v) and v == math.floor(v) and v >= lo and v <= hi) then
      return string.format("a whole number in %d..%d", lo, hi)
    end
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
-- (field -> rule; every default needs one). `name` prefixes messages; `level`
-- is how many calls up the effect's caller is (1: whoever called check).
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
    local want = rules[k](c[k])
    if want then error(string.format("%s.%s must be %s (got %s)", name, k, want, tostring(c[k])), level) end
  end
  return c
end

-- A deep copy, for putting a module's defaults into a pipeline's Options.
function options.copy(t)
  local c = {}
  for k, v in pairs(t) do c[k] = type(v) == "table" and options.copy(v) or v end
  return c
end

return options
