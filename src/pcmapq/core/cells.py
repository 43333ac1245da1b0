"""Cell states of an occupancy raster (the int8 values every raster of pcmapq uses)."""

#: Unknown (never observed), free and occupied cells.
UNKNOWN, FREE, OCCUPIED = -1, 0, 1
