"""contactfx: computational contact mechanics on FEniCSx."""

__version__ = "0.1.0"
