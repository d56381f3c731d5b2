"""Wide floats: ``LANES`` doubles handled as one value, so that a kernel does the same arithmetic on several
constraints at once (one SIMD instruction per operation, as Box2D v3's ``b2FloatW``).

A :data:`FloatW` is an LLVM vector ``<LANES x double>``.  Inside compiled kernels it comes from
:func:`load_w` (``LANES`` consecutive values of a float64 array) or :func:`splat_w` (one value in every
lane), goes back with :func:`store_w`, and supports ``+ - * /`` and unary ``-`` with another FloatW or a
float, :func:`max_w`, :func:`min_w`, :func:`abs_w`, :func:`sqrt_w` and the lane-wise choice
:func:`where_gt`; :func:`gather_w` and :func:`scatter_w` move columns of table rows named lane by
lane (each row read or written as one vector, then transposed).  The operations round exactly as the
scalar ones do (IEEE, no fast-math), so a wide kernel gives bit for bit the results of its scalar form.
``min`` and ``max`` follow Python's ``max(a, b)``: ``b if b > a else a``.

LLVM lowers the vectors to the machine's widest registers (one AVX-512 register, two AVX2 ones, four
SSE ones).  Under ``NUMBA_DISABLE_JIT`` a FloatW is a NumPy array of ``LANES`` values and every
operation is NumPy's, with the same results.
"""
import operator

import numpy as np
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic, models, overload, register_model

#: lanes of a FloatW: 8 doubles fill an AVX-512 register
LANES = 8


class FloatWType(types.Type):
    """Numba type of a wide float (``LANES`` doubles)."""

    def __init__(self):
        super().__init__(name=f"FloatW{LANES}")


#: the Numba type of a wide float
FloatW = FloatWType()
_VECTOR = ir.VectorType(ir.DoubleType(), LANES)
_I64 = ir.IntType(64)
_LANE_NUMBERS = ir.VectorType(ir.IntType(32), LANES)


@register_model(FloatWType)
class _FloatWModel(models.PrimitiveModel):
    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, _VECTOR)


def _lane_pointer(context, builder, array_type, array, offset):
    data = context.make_array(array_type)(context, builder, value=array).data
    return builder.bitcast(builder.gep(data, [offset]), _VECTOR.as_pointer())


def _is_float_array(a):
    return isinstance(a, types.Array) and a.ndim == 1 and a.dtype == types.float64


@intrinsic
def _load_w(typingctx, array, offset):
    if not (_is_float_array(array) and isinstance(offset, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        return builder.load(_lane_pointer(context, builder, signature.args[0], args[0], args[1]), align=8)
    return FloatW(array, offset), codegen


@intrinsic
def _store_w(typingctx, array, offset, value):
    if not (_is_float_array(array) and isinstance(offset, types.Integer) and isinstance(value, FloatWType)):
        return None

    def codegen(context, builder, signature, args):
        builder.store(args[2], _lane_pointer(context, builder, signature.args[0], args[0], args[1]), align=8)
        return context.get_dummy_value()
    return types.none(array, offset, value), codegen


@intrinsic
def _splat_w(typingctx, x):
    if not isinstance(x, (types.Float, types.Integer)):
        return None

    def codegen(context, builder, signature, args):
        value = context.cast(builder, args[0], signature.args[0], types.float64)
        vector = ir.Constant(_VECTOR, ir.Undefined)
        for lane in range(LANES):
            vector = builder.insert_element(vector, value, ir.Constant(ir.IntType(32), lane))
        return vector
    return FloatW(x), codegen


def _row_pointers(context, builder, signature, args):
    """Pointer to ``table[rows[offset + lane], col]`` for each lane (``table`` 2-D float64, ``rows`` int64)."""
    table = context.make_array(signature.args[0])(context, builder, value=args[0])
    rows = context.make_array(signature.args[1])(context, builder, value=args[1])
    row_bytes = cgutils.unpack_tuple(builder, table.strides)[0]
    origin = builder.add(builder.ptrtoint(table.data, _I64), builder.mul(args[3], ir.Constant(_I64, 8)))
    pointers = []
    for lane in range(LANES):
        row = builder.load(builder.gep(rows.data, [builder.add(args[2], ir.Constant(args[2].type, lane))]))
        pointers.append(builder.inttoptr(builder.add(origin, builder.mul(row, row_bytes)), _VECTOR.as_pointer()))
    return pointers


def _transpose(builder, vectors):
    """The ``LANES x LANES`` transpose of ``vectors`` (lane ``k`` of result ``l`` = lane ``l`` of input ``k``), by
    the butterfly of shuffles: at distance d = 1, 2, 4, ... vectors i and i + d swap their off-diagonal
    d-blocks."""
    v = list(vectors)
    d = 1
    while d < LANES:
        for i in range(LANES):
            if i & d:
                continue
            low = ir.Constant(_LANE_NUMBERS, [p if p & d == 0 else LANES + p - d for p in range(LANES)])
            high = ir.Constant(_LANE_NUMBERS, [p + d if p & d == 0 else LANES + p for p in range(LANES)])
            v[i], v[i + d] = builder.shuffle_vector(v[i], v[i + d], low), builder.shuffle_vector(v[i], v[i + d], high)
        d *= 2
    return v


def _first_lanes(count):
    """The mask of the first ``count`` lanes."""
    return ir.Constant(ir.VectorType(ir.IntType(1), LANES), [int(lane < count) for lane in range(LANES)])


def _masked_memory(builder, kind, pointer, count, value=None):
    """``llvm.masked.load`` or ``llvm.masked.store`` (``kind``) of the first ``count`` doubles at ``pointer``:
    the other lanes are never touched, so a row's last columns can be read without running past it."""
    mask = _first_lanes(count)
    alignment = ir.Constant(ir.IntType(32), 8)
    name = f"llvm.masked.{kind}.v{LANES}f64.p0"
    if kind == "load":
        function_type = ir.FunctionType(_VECTOR, [pointer.type, alignment.type, mask.type, _VECTOR])
        function = cgutils.get_or_insert_function(builder.module, function_type, name)
        return builder.call(function, [pointer, alignment, mask, ir.Constant(_VECTOR, None)])
    function_type = ir.FunctionType(ir.VoidType(), [_VECTOR, pointer.type, alignment.type, mask.type])
    function = cgutils.get_or_insert_function(builder.module, function_type, name)
    return builder.call(function, [value, pointer, alignment, mask])


def _offset_pointer(builder, pointer, columns):
    return builder.bitcast(builder.gep(builder.bitcast(pointer, ir.DoubleType().as_pointer()),
                                       [ir.Constant(_I64, columns)]), _VECTOR.as_pointer())


def _is_row_access(table, rows, offset, col):
    return (isinstance(table, types.Array) and table.ndim == 2 and table.dtype == types.float64
            and isinstance(rows, types.Array) and rows.ndim == 1 and rows.dtype == types.int64
            and isinstance(offset, types.Integer) and isinstance(col, types.Integer))


@intrinsic(prefer_literal=True)
def _gather_w(typingctx, table, rows, offset, col, count):
    if not (_is_row_access(table, rows, offset, col) and isinstance(count, types.IntegerLiteral)):
        return None
    columns = count.literal_value

    def codegen(context, builder, signature, args):
        # each lane's row read as one vector, then transposed: LANES loads and a few shuffles per block of
        # LANES columns, where a gather instruction per column would read every value on its own
        pointers = _row_pointers(context, builder, signature, args)
        values = []
        for first in range(0, columns, LANES):
            block = min(LANES, columns - first)
            rows = [_masked_memory(builder, "load", _offset_pointer(builder, p, first), block) for p in pointers]
            values += _transpose(builder, rows)[:block]
        return context.make_tuple(builder, signature.return_type, values)
    return types.UniTuple(FloatW, columns)(table, rows, offset, col, count), codegen


@intrinsic
def _scatter_w(typingctx, table, rows, offset, col, values):
    if not (_is_row_access(table, rows, offset, col) and isinstance(values, types.UniTuple)
            and isinstance(values.dtype, FloatWType)):
        return None

    def codegen(context, builder, signature, args):
        pointers = _row_pointers(context, builder, signature, args)
        values = cgutils.unpack_tuple(builder, args[4])
        for first in range(0, len(values), LANES):
            block = values[first:first + LANES]
            padded = list(block) + [ir.Constant(_VECTOR, None)] * (LANES - len(block))
            for pointer, row in zip(pointers, _transpose(builder, padded)):      # lanes in order
                _masked_memory(builder, "store", _offset_pointer(builder, pointer, first), len(block), row)
        return context.get_dummy_value()
    return types.none(table, rows, offset, col, values), codegen


def _vector_intrinsic(build, arity):
    """A Numba intrinsic on ``arity`` FloatW arguments whose LLVM code is ``build(builder, *vectors)``."""
    def codegen(context, builder, signature, args):
        return build(builder, *args)

    def check(*operands):
        if all(isinstance(t, FloatWType) for t in operands):
            return FloatW(*operands), codegen
        return None

    typers = {1: lambda typingctx, a: check(a), 2: lambda typingctx, a, b: check(a, b),
              4: lambda typingctx, a, b, x, y: check(a, b, x, y)}
    return intrinsic(typers[arity])


def _llvm_call(name):
    """The unary LLVM intrinsic ``name`` (e.g. ``llvm.sqrt``) on a whole vector."""
    def build(builder, a):
        function = cgutils.get_or_insert_function(builder.module, ir.FunctionType(_VECTOR, [_VECTOR]),
                                                  f"{name}.v{LANES}f64")
        return builder.call(function, [a])
    return build


_add_ww = _vector_intrinsic(lambda builder, a, b: builder.fadd(a, b), 2)
_sub_ww = _vector_intrinsic(lambda builder, a, b: builder.fsub(a, b), 2)
_mul_ww = _vector_intrinsic(lambda builder, a, b: builder.fmul(a, b), 2)
_div_ww = _vector_intrinsic(lambda builder, a, b: builder.fdiv(a, b), 2)
_neg_w = _vector_intrinsic(lambda builder, a: builder.fneg(a), 1)
_sqrt_w = _vector_intrinsic(_llvm_call("llvm.sqrt"), 1)
_abs_w = _vector_intrinsic(_llvm_call("llvm.fabs"), 1)
_where_gt = _vector_intrinsic(lambda builder, a, b, x, y: builder.select(builder.fcmp_ordered(">", a, b), x, y), 4)


def _operand(t):
    """``t`` as an operand of a wide operation: 'w' (a FloatW), 's' (a number, splat to every lane) or None."""
    if isinstance(t, FloatWType):
        return "w"
    if isinstance(t, (types.Float, types.Integer)):
        return "s"
    return None


def _overload_binary(python_operator, wide):
    @overload(python_operator)
    def implementation(a, b):
        kinds = _operand(a), _operand(b)
        if None in kinds or "w" not in kinds:
            return None
        if kinds == ("w", "w"):
            return lambda a, b: wide(a, b)
        if kinds == ("w", "s"):
            return lambda a, b: wide(a, _splat_w(b))
        return lambda a, b: wide(_splat_w(a), b)


for _python_operator, _wide_operation in ((operator.add, _add_ww), (operator.sub, _sub_ww),
                                          (operator.mul, _mul_ww), (operator.truediv, _div_ww)):
    _overload_binary(_python_operator, _wide_operation)


@overload(operator.neg)
def _overload_neg(a):
    if isinstance(a, FloatWType):
        return lambda a: _neg_w(a)


def load_w(array, offset):
    """The ``LANES`` values ``array[offset:offset + LANES]`` of a contiguous float64 array, as a FloatW."""
    return array[offset:offset + LANES].copy()


def store_w(array, offset, value):
    """Write the FloatW ``value`` to ``array[offset:offset + LANES]``."""
    array[offset:offset + LANES] = value


def gather_w(table, rows, offset, col, count):
    """``count`` (a constant) FloatW: the ``k``-th holds ``table[rows[offset + lane], col + k]`` in each
    lane, from a 2-D float64 table whose rows are named by the int64 array ``rows`` (never checked
    against the table's size)."""
    picked = rows[offset:offset + LANES]
    return tuple(table[picked, col + k].copy() for k in range(count))


def scatter_w(table, rows, offset, col, values):
    """Write lane ``i`` of the ``k``-th FloatW of the tuple ``values`` to ``table[rows[offset + i], col + k]``,
    lanes in order (a row named twice keeps the last lane's value)."""
    for k, value in enumerate(values):
        for lane in range(LANES):
            table[rows[offset + lane], col + k] = value[lane]


def splat_w(x):
    """The float ``x`` in every lane."""
    return np.full(LANES, float(x))


def where_gt(a, b, x, y):
    """Lane-wise ``x if a > b else y``."""
    return np.where(a > b, x, y)


def max_w(a, b):
    """Lane-wise ``max(a, b)`` as Python's: ``b if b > a else a``."""
    return np.where(b > a, b, a)


def min_w(a, b):
    """Lane-wise ``min(a, b)`` as Python's: ``b if b < a else a``."""
    return np.where(b < a, b, a)


def abs_w(a):
    """Lane-wise ``|a|``."""
    return np.abs(a)


def sqrt_w(a):
    """Lane-wise square root."""
    return np.sqrt(a)


# the compiled forms of the functions above
overload(load_w)(lambda array, offset: lambda array, offset: _load_w(array, offset))
overload(store_w)(lambda array, offset, value: lambda array, offset, value: _store_w(array, offset, value))
overload(gather_w, prefer_literal=True)(lambda table, rows, offset, col, count: lambda table, rows, offset, col, count:
                                        _gather_w(table, rows, offset, col, count))
overload(scatter_w)(lambda table, rows, offset, col, values: lambda table, rows, offset, col, values:
                    _scatter_w(table, rows, offset, col, values))
overload(splat_w)(lambda x: lambda x: _splat_w(x))
overload(where_gt)(lambda a, b, x, y: lambda a, b, x, y: _where_gt(a, b, x, y))
overload(max_w)(lambda a, b: lambda a, b: _where_gt(b, a, b, a))
overload(min_w)(lambda a, b: lambda a, b: _where_gt(a, b, b, a))
overload(abs_w)(lambda a: lambda a: _abs_w(a))
overload(sqrt_w)(lambda a: lambda a: _sqrt_w(a))
