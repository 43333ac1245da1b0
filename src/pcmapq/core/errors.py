"""The two ways a run can fail, each with its exit code."""


class InputError(Exception):
    """Bad input or usage: a file that cannot be read or makes no sense. Exit code 2.

    The message is one line that names the file and the problem.
    """

    exit_code = 2


class EvaluationError(Exception):
    """The inputs were read but could not be evaluated (e.g. alignment failed). Exit code 1."""

    exit_code = 1
