"""contactfx.scenes"""
