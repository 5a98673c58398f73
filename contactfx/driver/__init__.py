"""The driver: one pipeline (:func:`run`) for every problem kind; :func:`setup` builds a
problem without solving it."""

from contactfx.driver.pipeline import run, setup

__all__ = ["run", "setup"]
