"""The infant (and, with age and scale, other bodies) as data and a builder: body tables from
`data/`, the MjSpec builder, postures, joint-name groups, and the actuation models."""

from . import adult, growth, tables

# load_body (tables.py) grows the infant and builds the adult with these makers; they build on
# tables.py, which therefore cannot import them itself.
tables.MAKERS.update(grow=growth.grow_body, adult=adult.adult_tables)
