"""``--init-3d``: the 3D registration's start, read from ``identity``, 16 numbers or the file
``--transform`` writes; refused in one line when it is no rigid transform or cannot go with
the other options."""

from __future__ import annotations

import numpy as np
import pytest

from pcmapq.core.errors import InputError
from pcmapq.io.export import write_matrix
from pcmapq.settings import Settings
from pcmapq.settings.build import check
from pcmapq.settings.configs import AlignmentConfig
from pcmapq.settings.parsers import OptionError, parse_init_3d, show_init_3d
from testkit.poses import rotation_about

pytestmark = pytest.mark.unit


def pose(yaw: float, t: tuple[float, float, float]) -> np.ndarray:
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rotation_about([0.2, -0.1, 1.0], yaw), t
    return out


def test_identity_numbers_and_the_file_transform_writes_give_the_matrix(tmp_path):
    matrix = pose(33.0, (1.5, -2.0, 0.25))
    write_matrix(tmp_path / "t.txt", matrix)
    assert parse_init_3d("identity") == tuple(np.eye(4).ravel())
    from_file = np.reshape(parse_init_3d(str(tmp_path / "t.txt")), (4, 4))
    np.testing.assert_allclose(from_file, matrix, atol=1e-12)
    from_text = parse_init_3d(",".join(repr(float(v)) for v in matrix.ravel()))
    np.testing.assert_allclose(np.reshape(from_text, (4, 4)), matrix, atol=1e-12)
    three_rows = parse_init_3d(",".join(repr(float(v)) for v in matrix[:3].ravel()))
    assert three_rows == from_text
    # what the option shows reads back as the same matrix
    assert parse_init_3d(show_init_3d(from_text)) == from_text
    assert show_init_3d(parse_init_3d("identity")) == "identity"


def test_a_matrix_written_with_few_decimals_is_made_a_rotation():
    """Six decimals leave the rotation up to 1e-6 off; the start is made a rotation, so the
    registration's moves keep it rigid."""
    matrix = np.round(pose(71.0, (3.0, 4.0, -1.0)), 6)
    got = np.reshape(parse_init_3d(",".join(str(v) for v in matrix.ravel())), (4, 4))
    rotation = got[:3, :3]
    assert np.abs(rotation.T @ rotation - np.eye(3)).max() < 1e-12
    assert np.linalg.det(rotation) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(got, matrix, atol=2e-6)


@pytest.mark.parametrize(("text", "message"), [
    ("1,2,3", "16 finite numbers"),
    ("1,0,0,0,0,1,0,0,0,0,1,0,0,0,0,nan", "16 finite numbers"),
    ("2,0,0,0,0,1,0,0,0,0,1,0,0,0,0,1", "not a rigid transform"),
    ("0,1,0,0,1,0,0,0,0,0,1,0,0,0,0,1", "not a rigid transform"),  # a mirror
    ("1,0,0,0,0,1,0,0,0,0,1,0,0,0,1,1", "not a rigid transform"),
    ("no/such/file.txt", "no/such/file.txt: no such file"),
])
def test_what_is_no_rigid_transform_is_refused_naming_the_option(text, message):
    with pytest.raises(OptionError, match=message) as err:
        parse_init_3d(text)
    assert err.value.option == "--init-3d" and "\n" not in err.value.message


def test_a_file_of_other_things_is_refused_naming_it(tmp_path):
    path = tmp_path / "notes.txt"
    path.write_text("row one\nrow two\n")
    with pytest.raises(OptionError, match=f"{path} holds something else"):
        parse_init_3d(str(path))


@pytest.mark.parametrize(("alignment", "other"), [
    (AlignmentConfig(init_3d=tuple(np.eye(4).ravel()), enabled=False), "--no-align"),
    (AlignmentConfig(init_3d=tuple(np.eye(4).ravel()), scale=True), "--scale auto"),
])
def test_a_3d_start_does_not_go_with_no_alignment_or_a_scale(alignment, other):
    with pytest.raises(InputError, match=f"--init-3d and {other}"):
        check(Settings(alignment=alignment))


def test_a_3d_start_does_not_go_with_a_plan_start():
    from pcmapq.core.transform import Similarity2D

    settings = Settings(alignment=AlignmentConfig(init=Similarity2D(1.0, 2.0, 0.5),
                                                  init_3d=tuple(np.eye(4).ravel())))
    with pytest.raises(InputError, match="--init-3d and --init cannot go together"):
        check(settings)
    check(Settings(alignment=AlignmentConfig(init_3d=tuple(np.eye(4).ravel()))))
