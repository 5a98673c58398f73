"""contactfx.validation"""
