"""contactfx.io"""
