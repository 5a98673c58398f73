"""The driver: one pipeline (:func:`run`) for every problem kind."""

from contactfx.driver.pipeline import run

__all__ = ["run"]
