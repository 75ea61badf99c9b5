-- Option checking shared by effect modules: each effect copies its defaults,
-- refuses unknown names, and tests each value with these predicates. Errors
-- point at the pipeline line that called the effect's render function.
local check = {}

function check.whole(v, lo, hi)
  return type(v) == "number" and v == math.floor(v) and v >= lo and v <= hi -- false for NaN
end

function check.within(v, lo, hi)
  return type(v) == "number" and v >= lo and v <= hi -- false for NaN
end

-- o with every missing field of `defaults` filled in; unknown fields are an
-- error naming "<prefix>.<field>". `level` is the caller to blame, counted
-- from the function that calls options().
function check.options(o, defaults, prefix, level)
  local c = {}
  for k, v in pairs(defaults) do
    if o == nil or o[k] == nil then c[k] = v else c[k] = o[k] end
  end
  for k in pairs(o or {}) do
    if defaults[k] == nil then
      error(string.format("%s.%s is not an option of %s", prefix, tostring(k), prefix), level + 1)
    end
  end
  return c
end

-- Raises "<msg> (got <v>)" at `level` (counted from the caller of need) when not ok.
function check.need(ok, msg, v, level)
  if not ok then error(string.format("%s (got %s)", msg, tostring(v)), level + 1) end
end

return check
