"""Exports of a specification to other modelling languages; today SysML v2 (`earl export sysml`).

Exports read the model only: they never import or run code a spec names.
"""

from earl.export.sysml import export_sysml, library_text

__all__ = ["export_sysml", "library_text"]
