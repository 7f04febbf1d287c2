"""The base of every case-file section and the number types they share."""

from __future__ import annotations

from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field

from granulate.input_errors import NOT_BOOL

Vector = list[Annotated[float, NOT_BOOL]]
Positive = Annotated[float, Field(gt=0, allow_inf_nan=False), NOT_BOOL]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False), NOT_BOOL]
Finite = Annotated[float, Field(allow_inf_nan=False), NOT_BOOL]


class Spec(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)
