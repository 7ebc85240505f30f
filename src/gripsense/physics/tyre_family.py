"""The tyre-curve family made from real tyres, as constants: the Magic Formula normalised shapes
(C_s, E) that cover every published tyre file of the library, and each tyre category's members
(``docs/physics.md`` §14.3). :mod:`gripsense.config.tyre_library` builds them from the bundled
files (``tests/physics/test_tyre_library.py`` checks that it still does); nothing is read here.
"""

from __future__ import annotations

__all__ = ["CATEGORIES", "CATEGORY_MEMBERS", "FAMILY_MEMBERS", "category_members"]

CATEGORIES = ("passenger", "suv", "performance", "racing", "truck")
"""Tyre categories a tyre's ``shape`` may name (its members only)."""


FAMILY_MEMBERS: tuple[tuple[float, float], ...] = (
    (1.14, -0.76),
    (1.18, -0.18),
    (1.2, 0.52),
    (1.24, 0.22),
    (1.28, -0.32),
    (1.3, -1.06),
    (1.38, -0.4),
    (1.38, 0.14),
    (1.42, -1.26),
    (1.46, -0.2),
    (1.48, -0.6),
    (1.5, -2.08),
    (1.5, -0.76),
    (1.72, 0.24),
    (1.76, -0.2),
    (1.82, 0.22),
)
"""The data-made family's (C_s, E): :func:`gripsense.config.tyre_library.build_family` on the
library's files (16 shapes)."""

CATEGORY_MEMBERS: dict[str, tuple[tuple[float, float], ...]] = {
    "passenger": ((1.24, 0.22), (1.28, -0.32), (1.3, -1.06), (1.38, -0.4), (1.46, -0.2)),
    "suv": (
        (1.24, 0.22),
        (1.28, -0.32),
        (1.3, -1.06),
        (1.46, -0.2),
        (1.48, -0.6),
        (1.72, 0.24),
        (1.76, -0.2),
        (1.82, 0.22),
    ),
    "performance": ((1.38, 0.14), (1.46, -0.2), (1.48, -0.6), (1.5, -2.08), (1.5, -0.76)),
    "racing": ((1.24, 0.22),),
    "truck": (
        (1.14, -0.76),
        (1.18, -0.18),
        (1.2, 0.52),
        (1.24, 0.22),
        (1.28, -0.32),
        (1.3, -1.06),
        (1.38, -0.4),
        (1.38, 0.14),
        (1.42, -1.26),
        (1.46, -0.2),
    ),
}
"""Each category's members (C_s, E): :func:`gripsense.config.tyre_library.build_family` on the
library's files."""


def category_members(category: str) -> tuple[tuple[float, float], ...]:
    """The members of :data:`FAMILY_MEMBERS` that cover one category's files.

    Parameters
    ----------
    category : str
        One of :data:`CATEGORIES`.

    Returns
    -------
    tuple of (float, float)
        (C_s, E) of the members.
    """
    if category not in CATEGORIES:
        raise ValueError(f"tyre category {category!r}: use one of {', '.join(CATEGORIES)}")
    return CATEGORY_MEMBERS[category]
