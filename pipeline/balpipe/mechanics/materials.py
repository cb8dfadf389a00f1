"""The named materials a counterweight part may be made of, with their densities (kg/m^3).

A spec names one of these (``material: steel``) or gives its own density (``density: 7600
kg/m^3``, with any name it likes as ``material``). The densities are the usual handbook values
at room temperature, rounded as designers use them; a part whose mass must be exact to a
particular alloy's density should give that density. This table is the only place balpipe
holds densities (docs/parts.md lists it).
"""

from __future__ import annotations

#: name -> density, kg/m^3
DENSITIES: dict[str, float] = {
    "steel": 7850.0,
    "cast_iron": 7200.0,
    "brass": 8500.0,
    "aluminium": 2700.0,
    "tungsten_alloy": 17000.0,
}


def density_of(material: str | None, density: float | None) -> float:
    """The density of a part: ``density`` when given, else the named ``material``'s. Raises
    KeyError naming the known materials when neither gives one."""
    if density is not None:
        return float(density)
    if material is None or material not in DENSITIES:
        raise KeyError(f"unknown material {material!r}: give its density, or one of "
                       + ", ".join(f"{k} ({v:g} kg/m^3)" for k, v in DENSITIES.items()))
    return DENSITIES[material]
