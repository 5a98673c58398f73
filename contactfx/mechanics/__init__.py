"""contactfx.mechanics"""
