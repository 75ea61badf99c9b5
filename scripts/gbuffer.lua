-- The G-buffer of seed 000 (lines 1229-1259): declare its targets for a frame
-- and record the geometry pass that fills them.
local gbuffer = {}

-- Targets at `scale` of the output (1 by default). Fields: clr, nrm, dpt, mat, depth.
function gbuffer.targets(scale)
  scale = scale or 1
  return {
    clr = target{ "gbuffer.clr", format = "rgba8", scale = scale },      -- albedo, rho
    nrm = target{ "gbuffer.nrm", format = "rgba16f", scale = scale },    -- world normal, shininess
    dpt = target{ "gbuffer.dpt", format = "r32f", scale = scale },       -- linear depth / far
    mat = target{ "gbuffer.mat", format = "rgba8", scale = scale },      -- k_a, k_d, k_s, coverage
    depth = target{ "gbuffer.depth", format = "depth32f", scale = scale },
  }
end

-- Draws the scene with material technique `technique` ("std") into G;
-- `materials` (optional) overrides material parameters by name:
-- { wall = { color = { 1, 0, 0 }, ks = 0.2 } }.
function gbuffer.render(G, technique, materials)
  scene{ "gbuffer", technique = technique or "std", out = { G.clr, G.nrm, G.dpt, G.mat },
         depth = G.depth, clear = { 0, 0, 0, 0 }, materials = materials }
  return G
end

-- The inputs table a lighting pass takes.
function gbuffer.inputs(G)
  return { clr = G.clr, nrm = G.nrm, dpt = G.dpt, mat = G.mat }
end

return gbuffer
