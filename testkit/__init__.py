"""What tests, benchmarks and tools share, outside the installed package (a folder of the
checkout, imported from its root): synthetic plans and maps with known answers
(:mod:`~testkit.synth`), written as files (:mod:`.files`), CARMEN logs (:mod:`.carmen`) and ROS
recordings (:mod:`.recordings`); the command line as a test runs it (:mod:`.command`); known
poses (:mod:`.poses`); the checkout's sample, references and real data (:mod:`.paths`), the
real data sets' cases (:mod:`.realdata`), KITTI's calibration and drifted maps (:mod:`.kitti`);
MapEval's AWD and SCS written plainly (:mod:`.mapeval`); stored
references and their comparison (:mod:`.reference`), timed runs (:mod:`.runs`), the drift
ladder (:mod:`.drift`), the soak (:mod:`.soak`), the labelled same-place corpus
(:mod:`.corpus`), a small batch (:mod:`.batch`) and the report's viewer probed in Chromium
(:mod:`.viewer`)."""
