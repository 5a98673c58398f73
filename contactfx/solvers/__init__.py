"""contactfx.solvers"""
