"""contactfx.contact"""
