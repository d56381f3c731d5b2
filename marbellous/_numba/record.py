"""Compiled records (Numba StructRefs) handed to a kernel as one int, and kernels entered without typing.

A call from Python into a compiled kernel unboxes every array argument (its data pointer, shape and
strides read and a reference taken): about 35 ns per array through the compiled entry point, 60 ns
through Numba's dispatcher, which also types each argument first.  A StructRef holding the arrays
crosses the boundary as one pointer (~0.17 us per call); its address as a plain int crosses in ~10 ns,
and :func:`reader` turns the int back into the record inside the kernel.

Inside a kernel, every copy of a record variable (a call, an inlined function's argument) counts a
reference with two atomic operations, and reading one of its arrays counts another: a step made of
dozens of inlined stages over a record would spend a few hundred nanoseconds on that alone.  A
:func:`view` of a record is the same data seen through a type without reference counting: passing it
costs nothing, and reading an array field gives a borrowed array (``jit.borrow``).  A view is valid
while the record it was made from is alive; scalar fields can be written through it, array fields only
through the record.

With ``NUMBA_DISABLE_JIT`` (kernels as plain Python) a record is a namespace, its "address" and its
view the namespace itself.
"""
from types import SimpleNamespace

import numba
from numba import types
from numba.core import cgutils
from numba.core.typing.templates import AttributeTemplate
from numba.experimental import structref
from numba.experimental.structref import _Utils
from numba.extending import (infer_getattr, intrinsic, lower_getattr_generic, lower_setattr_generic, models,
                             register_model)

from .jit import _borrow_codegen, njit, njit_inline


def new_record_function():
    """``structref.new``, or a namespace maker under ``NUMBA_DISABLE_JIT``: call it inside a kernel with
    the record's type to make an empty record."""
    if numba.config.DISABLE_JIT:
        def new(_type):
            return SimpleNamespace()
        return new
    return structref.new


def reader(record_type):
    """An intrinsic ``at(address)`` that returns the record of type ``record_type`` whose memory-info block
    is at ``address`` (:func:`record_address`), as a new reference.  Under ``NUMBA_DISABLE_JIT``, the
    identity."""
    if numba.config.DISABLE_JIT:
        def at(address):
            return address
        return at

    @intrinsic
    def at(typingctx, address):
        def codegen(context, builder, signature, args):
            ref = cgutils.create_struct_proxy(record_type)(context, builder)
            ref.meminfo = builder.inttoptr(args[0], ref.meminfo.type)
            value = ref._getvalue()
            context.nrt.incref(builder, record_type, value)
            return value
        return record_type(types.intp), codegen
    return at


@intrinsic
def _meminfo_address(typingctx, record):
    def codegen(context, builder, signature, args):
        ref = cgutils.create_struct_proxy(signature.args[0])(context, builder, value=args[0])
        return builder.ptrtoint(ref.meminfo, context.get_value_type(types.intp))
    return types.intp(record), codegen


@njit
def _address(record):
    return _meminfo_address(record)


def record_address(record):
    """The address (an int) of ``record``'s memory-info block, which a :func:`reader` turns back into the
    record inside a kernel.  Valid only while the caller keeps ``record`` alive.  With
    ``NUMBA_DISABLE_JIT`` the record itself."""
    if numba.config.DISABLE_JIT:
        return record
    return _address(record)


def array_address(array):
    """The address (an int) of a contiguous int64 ``array``'s first element, which :func:`int64_array_at` turns
    back into the array inside a kernel: an int crosses into a kernel ~50 ns faster than an array.  Valid
    while the caller keeps ``array`` alive.  With ``NUMBA_DISABLE_JIT`` the array itself."""
    if numba.config.DISABLE_JIT:
        return array
    return array.ctypes.data


@intrinsic
def _int64_pointer(typingctx, address):
    pointer = types.CPointer(types.int64)

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(pointer))
    return pointer(types.intp), codegen


def int64_array_at(address, n):
    """Inside a kernel, the ``n`` int64 values at ``address`` (:func:`array_address`) as an array (borrowed:
    valid while the caller keeps the array alive).  Plain Python: ``address`` is the array itself."""
    return address


if not numba.config.DISABLE_JIT:
    @njit_inline
    def int64_array_at(address, n):          # noqa: F811 (the compiled form of the function above)
        return numba.carray(_int64_pointer(address), n)


def compiled_entry(kernel, *arguments):
    """The compiled entry point of ``kernel`` for ``arguments``' types (compiled or loaded from the cache on
    first use): calling it skips the dispatcher's typing of the arguments (~60 ns for an int, ~0.5 us for
    a record).  With ``NUMBA_DISABLE_JIT`` the kernel itself."""
    if numba.config.DISABLE_JIT:
        return kernel
    key = tuple(numba.typeof(a) for a in arguments)
    if key not in kernel.overloads:
        kernel.compile(key)
    return kernel.overloads[key].entry_point


class RecordView(types.Type):
    """Numba type of a view of the records of one StructRef type (see the module docstring)."""

    def __init__(self, record_type):
        self.record_type = record_type
        super().__init__(name=f"RecordView({record_type})")


@register_model(RecordView)
class _RecordViewModel(models.StructModel):
    """A view is the record's memory-info pointer as a plain pointer: no reference is counted."""

    def __init__(self, dmm, fe_type):
        super().__init__(dmm, fe_type, [("meminfo", types.voidptr)])


@infer_getattr
class _RecordViewAttributes(AttributeTemplate):
    key = RecordView

    def generic_resolve(self, typ, attr):
        return typ.record_type.field_dict.get(attr)


def _record_data(context, builder, view_type, view):
    """The data struct of the record that ``view`` sees."""
    record_type = view_type.record_type
    meminfo = cgutils.create_struct_proxy(view_type)(context, builder, value=view).meminfo
    ref = cgutils.create_struct_proxy(record_type)(context, builder)
    ref.meminfo = builder.bitcast(meminfo, ref.meminfo.type)
    return _Utils(context, builder, record_type).get_data_struct(ref._getvalue())


@lower_getattr_generic(RecordView)
def _record_view_getattr(context, builder, typ, val, attr):
    value = getattr(_record_data(context, builder, typ, val), attr)
    field_type = typ.record_type.field_dict[attr]
    if isinstance(field_type, types.Array):
        return _borrow_codegen(context, builder, field_type(field_type), [value])
    return value


@lower_setattr_generic(RecordView)
def _record_view_setattr(context, builder, sig, args, attr):
    view_type, value_type = sig.args
    field_type = view_type.record_type.field_dict[attr]
    if context.data_model_manager[field_type].has_nrt_meminfo():
        raise TypeError(f"{attr}: a reference-counted field is written through the record, not a view")
    data = _record_data(context, builder, view_type, args[0])
    setattr(data, attr, context.cast(builder, args[1], value_type, field_type))


def viewer(record_type):
    """An intrinsic ``view(record)`` that returns a :class:`RecordView` of a record of ``record_type``.
    Under ``NUMBA_DISABLE_JIT``, the identity."""
    if numba.config.DISABLE_JIT:
        def view(record):
            return record
        return view
    view_type = RecordView(record_type)

    @intrinsic
    def view(typingctx, record):
        if record != record_type:
            return None

        def codegen(context, builder, signature, args):
            ref = cgutils.create_struct_proxy(record_type)(context, builder, value=args[0])
            out = cgutils.create_struct_proxy(view_type)(context, builder)
            out.meminfo = builder.bitcast(ref.meminfo, out.meminfo.type)
            return out._getvalue()
        return view_type(record), codegen
    return view
