"""The drift ladder (testkit.drift): the steps where a detector's f1 does not fall."""

from __future__ import annotations

from testkit import drift


def test_not_falling_lists_the_steps_where_f1_does_not_fall() -> None:
    def rung(level: float, harris: float, sift: float | None):
        return drift.Rung(level=level, verdict="same place", pose_error_m=0.0,
                          yaw_error_deg=0.0, fitness=1.0, quality={}, precision={},
                          f1={"harris": harris, "sift": sift},
                          accuracy_mean_m=None, completeness_mean_m=None, chamfer_m=None,
                          f_at_01=None, seconds=0.0)

    rungs = [rung(0.0, 1.0, 1.0), rung(0.01, 0.5, None), rung(0.02, 0.5, 0.4),
             rung(0.04, 0.6, 0.3)]
    assert drift.not_falling(rungs) == [("harris", 0.01, 0.02, 0.5, 0.5),
                                        ("harris", 0.02, 0.04, 0.5, 0.6)]
    assert drift.falls_text(rungs) == ("f1 does not fall: harris from 1 to 2 % (0.500, 0.500); "
                                       "harris from 2 to 4 % (0.500, 0.600).")
    assert drift.falls_text(rungs[:2]) == "f1 falls at every step for every detector."
