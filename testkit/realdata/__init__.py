"""The real data sets of ``../shared/data`` as tests and the validation (``bench/validation``)
run them: each set's files, the settings it is scored with and its expected answers, one
module per set (floor plans, Gazebo, Halmstad, the LiDAR pair, the Freiburg 079 turns, the
same-place pairs, the no-reference grid pairs). Tests check them; bench measures and writes
docs/validation.md from them."""
