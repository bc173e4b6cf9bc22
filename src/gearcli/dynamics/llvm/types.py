"""The LLVM types of the generated code: doubles, booleans, 64-bit integers and their pointers,
and the fast-math flags of its arithmetic (only ``contract``: NaN must reach the sign search)."""
from __future__ import annotations

import llvmlite.ir as ir

D = ir.DoubleType()
I1 = ir.IntType(1)
I64 = ir.IntType(64)
DP = D.as_pointer()
I64P = I64.as_pointer()
FLAGS = ("contract",)
