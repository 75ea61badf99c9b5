-- The G-buffer of seed 000 (lines 1229-1259): declare its targets for a frame
-- and record the geometry pass that fills them.
local gbuffer = {}

-- Targets at `scale` of the output (1 by default). Fields: clr, nrm, dpt, mat, depth;
-- for material technique "pbr" also emi (emitted radiance, added after lighting);
-- with `velocity` also vel (shaders/velocity.glsl: screen motion since the previous
-- frame in output pixels, the previous view depth, coverage), only for a frame that
-- reads it (motion blur, temporal reuse).
function gbuffer.targets(scale, technique, velocity)
  scale = scale or 1
  local G = {
    clr = target{ "gbuffer.clr", format = "rgba8", scale = scale },      -- albedo, rho
    nrm = target{ "gbuffer.nrm", format = "rgba8", scale = scale },      -- world normal, shininess (gbuffer_normal_encode)
    dpt = target{ "gbuffer.dpt", format = "r32f", scale = scale },       -- linear depth / far
    mat = target{ "gbuffer.mat", format = "rgba8", scale = scale },      -- k_a, k_d, k_s, coverage
    depth = target{ "gbuffer.depth", format = "depth32f", scale = scale },
  }
  if technique == "pbr" then G.emi = target{ "gbuffer.emi", format = "rgba16f", scale = scale } end
  if velocity then G.vel = target{ "gbuffer.vel", format = "rgba16f", scale = scale } end
  return G
end

-- Draws the scene with material technique `technique` ("std" Phong, or "pbr"
-- glTF metallic-roughness, which writes the same channels) into G;
-- `materials` (optional) overrides material parameters by name:
-- { wall = { color = { 1, 0, 0 }, ks = 0.2 } }; `simplify` (optional, pixels): a mesh
-- node draws its coarsest simplified copy (made at load) that errs by at most that
-- many pixels where it comes nearest the camera (0 or nil: every mesh whole).
function gbuffer.render(G, technique, materials, simplify)
  local out, defines = { G.clr, G.nrm, G.dpt, G.mat }, {}
  if G.emi then out[#out + 1] = G.emi end
  if G.vel then
    defines.VELOCITY = #out -- its output location
    out[#out + 1] = G.vel
  end
  scene{ "gbuffer", technique = technique or "std", out = out, defines = defines,
         depth = G.depth, clear = { 0, 0, 0, 0 }, materials = materials, simplify = simplify }
  G.phong_only = (technique or "std") == "std" -- no pixel carries the pbr technique's mark
  return G
end

-- Adds to a lighting pass's defines the scene's light set, when the pipeline
-- put one in G.lights (light_set(): lighting.glsl then evaluates each light
-- unrolled, for its kind alone, instead of the general loop).
function gbuffer.lights(G, defines)
  for k, v in pairs(G.lights or {}) do defines[k] = v end
  return defines
end

-- Adds to a lighting pass's defines what G says of its pixels: PHONG_ONLY when
-- the std technique drew them all (gbuffer.glsl then compiles no GGX); and
-- the light set (gbuffer.lights).
function gbuffer.defines(G, defines)
  defines.PHONG_ONLY = G.phong_only
  return gbuffer.lights(G, defines)
end

-- The inputs table a lighting pass takes.
function gbuffer.inputs(G)
  return { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat }
end

return gbuffer
