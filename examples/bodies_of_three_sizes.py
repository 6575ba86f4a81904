"""Three bodies in one world: an 18-month-old (scale 1), a 3-4-year-old (1.3) and a
caregiver-sized body (2.2), standing on a circle; writes a labelled picture of the scene (each
body's scale, height and mass under it) and prints the masses.

    python examples/bodies_of_three_sizes.py [out.png]

The same picture: ``mimo-social figure bodies-three-sizes out.png``
(:func:`mimo_social.figures.save_three_sizes_png`). The scaling laws (mass s^3, inertia s^5,
torque s^4 x strength, ...) are in docs/bodies.md.
"""

import sys

from mimo_social.figures import save_three_sizes_png


def main(path: str = "bodies_of_three_sizes.png") -> None:
    print(f"wrote {save_three_sizes_png(path)}")


if __name__ == "__main__":
    main(*sys.argv[1:])
