"""The infant (and, with age and scale, other bodies) as data and a builder: body tables from
`data/`, the MjSpec builder, postures, joint-name groups, and the actuation models."""
