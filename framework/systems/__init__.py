"""The pipeline's stages, one module each: movement, continuous detection, broad phase, narrow
phase (with collision events) and response. Each reads what the previous one wrote."""
