"""What every block of the result's document is: its keys exactly its fields, in order."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

Point = tuple[float, float]
Matrix = list[list[float]]
Point3 = tuple[float, float, float]


class Block(BaseModel):
    """A block of the document: its keys are exactly its fields, in their order."""

    model_config = ConfigDict(extra="forbid", frozen=True, use_attribute_docstrings=True)
