"""Writes a JAX function as an ONNX graph: its jaxpr, equation by equation, as ONNX operators (opset OPSET).

    model = jaxpr_to_onnx.convert(fn, [jax.ShapeDtypeStruct((1, 64, 80, 3), jnp.uint8), ...], ["rgb", ...], ["depth"])
    onnx.save(model, "m.onnx")

Why a translator of our own and not jax2onnx (ARCHITECTURE.md, "ONNX"): jax2onnx 0.17.1 installs beside lipjax only
with orbax-checkpoint held below 0.11.37 and some 25 packages lipjax does not use, and it exports the default graph
only after two library functions are rewritten around its gaps; this module needs only the `onnx` package. It
translates the primitives lipjax's inference graphs use (the LIP models, the initial estimates, the resizes; PRIMITIVES
lists them) and names any other one in a one-line NotImplementedError. Since the graph is the jaxpr of the function
JAX runs, the exported model computes what the JAX model computes, to float32 rounding (tests/test_onnx_export.py
checks each primitive and whole models under onnxruntime).

How:
  - Every value is either a numpy array known at conversion time (the function's closed-over constants, such as
    a model's parameters, and anything computed from constants alone: constant folding, which keeps a kernel's
    rearrangement out of the graph) or the name of a tensor of the graph.
  - Nested jaxprs (jit, custom_jvp_call, ...) are inlined, `scan` is unrolled (its length is static).
  - Layouts: ONNX's Conv is NCHW / OIHW; a convolution's operands are transposed to it by its dimension numbers
    and the result back. A reduce_window (a max over a small window) is a max over shifted slices.
  - Shapes are static: every tensor has the shape of its jaxpr variable (no dynamic axes).
  - uint8 / int8 / int16 operands of comparisons and max / min are widened to int32 first (onnxruntime has no
    kernels for them).
"""
from __future__ import annotations

import itertools
from collections.abc import Callable, Sequence

import jax
import jax.extend.core as jcore
import numpy as np

OPSET = 18
FOLD_MAX_ELEMENTS = 1 << 12  # a folded constant may be larger than this only when no larger than an input


class _Graph:
    """The nodes and initializers being written, with unique names."""

    def __init__(self):
        self.nodes, self.initializers = [], []
        self.value_info = {}  # tensor name -> its declared type and shape
        self._names = itertools.count()

    def name(self, hint: str = "t") -> str:
        return f"{hint}_{next(self._names)}"

    def const(self, value) -> str:
        import onnx.numpy_helper

        name = self.name("c")
        self.initializers.append(onnx.numpy_helper.from_array(np.asarray(value), name))
        return name

    def tensor(self, value) -> str:
        """The graph tensor of a value: a name as is, a known array as an initializer."""
        return value if isinstance(value, str) else self.const(value)

    def node(self, op: str, inputs: Sequence, outputs: int = 1, **attrs):
        """Adds `op` on `inputs` (names or arrays); returns its output name, or names when outputs > 1."""
        import onnx.helper

        names = [self.name(op.lower()) for _ in range(outputs)]
        self.nodes.append(onnx.helper.make_node(op, [self.tensor(i) for i in inputs], names, **attrs))
        return names[0] if outputs == 1 else names


def _onnx_dtype(dtype) -> int:
    import onnx.helper

    return onnx.helper.np_dtype_to_tensor_dtype(np.dtype(dtype))


def _value_info(name: str, aval):
    """The declared type and shape of a tensor: those of its jaxpr variable."""
    import onnx.helper

    return onnx.helper.make_tensor_value_info(name, _onnx_dtype(aval.dtype), list(aval.shape))


def _i64(values) -> np.ndarray:
    return np.asarray(values, np.int64)


# ---- element-wise ----

_BINARY = {"add": "Add", "sub": "Sub", "mul": "Mul", "div": "Div", "max": "Max", "min": "Min", "pow": "Pow",
           "lt": "Less", "le": "LessOrEqual", "gt": "Greater", "ge": "GreaterOrEqual", "eq": "Equal"}
_UNARY = {"neg": "Neg", "exp": "Exp", "log": "Log", "sqrt": "Sqrt", "abs": "Abs", "floor": "Floor", "ceil": "Ceil",
          "tanh": "Tanh", "logistic": "Sigmoid", "sign": "Sign", "erf": "Erf", "copy": "Identity",
          "copy_p": "Identity"}
# No onnxruntime kernels for compares, max and min of these.
_NARROW_INTS = tuple(np.dtype(t) for t in (np.uint8, np.int8, np.uint16, np.int16))


def _elementwise(g: _Graph, op: str, ins, dtype, out_dtype):
    """`op` on `ins` of `dtype`, narrow integers widened to int32 and the result cast back to `out_dtype`."""
    if np.dtype(dtype) in _NARROW_INTS and op not in ("Add", "Sub", "Mul", "Div"):
        out = g.node(op, [g.node("Cast", [x], to=_onnx_dtype(np.int32)) for x in ins])
        return out if np.dtype(out_dtype) == np.bool_ else g.node("Cast", [out], to=_onnx_dtype(out_dtype))
    return g.node(op, ins)


def _binary(g: _Graph, eqn, ins):
    return _elementwise(g, _BINARY[eqn.primitive.name], ins, eqn.invars[0].aval.dtype, eqn.outvars[0].aval.dtype)


def _logical(g: _Graph, eqn, ins):
    boolean = eqn.invars[0].aval.dtype == np.bool_
    op = {"and": ("And", "BitwiseAnd"), "or": ("Or", "BitwiseOr"), "xor": ("Xor", "BitwiseXor"),
          "not": ("Not", "BitwiseNot")}[eqn.primitive.name][0 if boolean else 1]
    return g.node(op, ins)


def _unary(g: _Graph, eqn, ins):
    return g.node(_UNARY[eqn.primitive.name], ins)


def _ne(g: _Graph, eqn, ins):
    return g.node("Not", [_elementwise(g, "Equal", ins, eqn.invars[0].aval.dtype, np.bool_)])


def _rsqrt(g: _Graph, eqn, ins):
    return g.node("Reciprocal", [g.node("Sqrt", ins)])


def _square(g: _Graph, eqn, ins):
    return g.node("Mul", [ins[0], ins[0]])


def _log1p(g: _Graph, eqn, ins):
    return g.node("Log", [g.node("Add", [ins[0], np.asarray(1, eqn.invars[0].aval.dtype)])])


def _integer_pow(g: _Graph, eqn, ins):
    y = eqn.params["y"]
    if y == 2:
        return g.node("Mul", [ins[0], ins[0]])
    return g.node("Pow", [ins[0], np.asarray(y, eqn.invars[0].aval.dtype)])


def _round(g: _Graph, eqn, ins):
    if eqn.params["rounding_method"] == jax.lax.RoundingMethod.TO_NEAREST_EVEN:
        return g.node("Round", ins)
    x = ins[0]  # away from zero: sign(x) floor(|x| + 1/2)
    half = np.asarray(0.5, eqn.invars[0].aval.dtype)
    return g.node("Mul", [g.node("Sign", [x]), g.node("Floor", [g.node("Add", [g.node("Abs", [x]), half])])])


def _is_finite(g: _Graph, eqn, ins):
    return g.node("Not", [g.node("Or", [g.node("IsInf", ins), g.node("IsNaN", ins)])])


def _convert(g: _Graph, eqn, ins):
    return g.node("Cast", ins, to=_onnx_dtype(eqn.params["new_dtype"]))


def _select_n(g: _Graph, eqn, ins):
    which, *cases = ins
    if eqn.invars[0].aval.dtype == np.bool_:
        if len(cases) != 2:
            raise NotImplementedError("select_n with a boolean predicate and more than two cases")
        return g.node("Where", [which, cases[1], cases[0]])
    out = cases[0]
    for k, case in enumerate(cases[1:], start=1):
        out = g.node("Where", [g.node("Equal", [which, np.asarray(k, eqn.invars[0].aval.dtype)]), case, out])
    return out


def _clamp(g: _Graph, eqn, ins):
    lo, x, hi = ins
    dtype = eqn.invars[1].aval.dtype
    return _elementwise(g, "Max", [_elementwise(g, "Min", [x, hi], dtype, dtype), lo], dtype, dtype)


# ---- shapes ----

def _shape_of(eqn) -> tuple[int, ...]:
    return tuple(eqn.outvars[0].aval.shape)


def _reshape(g: _Graph, eqn, ins):
    return g.node("Reshape", [ins[0], _i64(_shape_of(eqn))])


def _broadcast_in_dim(g: _Graph, eqn, ins):
    shape, dims = eqn.params["shape"], eqn.params["broadcast_dimensions"]
    operand = eqn.invars[0].aval.shape
    kept = [1] * len(shape)
    for axis, size in zip(dims, operand):
        kept[axis] = size
    x = g.node("Reshape", [ins[0], _i64(kept)]) if tuple(kept) != tuple(operand) else ins[0]
    return g.node("Expand", [x, _i64(shape)]) if tuple(kept) != tuple(shape) else x


def _transpose(g: _Graph, eqn, ins):
    return g.node("Transpose", ins, perm=list(eqn.params["permutation"]))


def _slice(g: _Graph, eqn, ins):
    start, limit = eqn.params["start_indices"], eqn.params["limit_indices"]
    steps = eqn.params["strides"] or (1,) * len(start)
    return g.node("Slice", [ins[0], _i64(start), _i64(limit), _i64(range(len(start))), _i64(steps)])


def _rev(g: _Graph, eqn, ins):
    """lax.rev (x[..., ::-1] on `dimensions`): a Slice with step -1 from the last element past the first."""
    axes = list(eqn.params["dimensions"])
    last, past_first, step = [-1] * len(axes), [np.iinfo(np.int64).min] * len(axes), [-1] * len(axes)
    return g.node("Slice", [ins[0], _i64(last), _i64(past_first), _i64(axes), _i64(step)])


def _pad(g: _Graph, eqn, ins):
    config = eqn.params["padding_config"]
    if any(interior for _, _, interior in config):
        raise NotImplementedError("pad with interior padding")
    shape = eqn.invars[0].aval.shape
    x = ins[0]
    if any(lo < 0 or hi < 0 for lo, hi, _ in config):  # negative padding crops
        starts = [max(-lo, 0) for lo, _, _ in config]
        ends = [n - max(-hi, 0) for n, (_, hi, _) in zip(shape, config)]
        x = g.node("Slice", [x, _i64(starts), _i64(ends), _i64(range(len(shape)))])
    pads = [max(lo, 0) for lo, _, _ in config] + [max(hi, 0) for _, hi, _ in config]
    if not any(pads):
        return x
    return g.node("Pad", [x, _i64(pads), ins[1]], mode="constant")


def _concatenate(g: _Graph, eqn, ins):
    ins = [x for x, v in zip(ins, eqn.invars) if np.prod(v.aval.shape) > 0]  # ONNX's empty tensors are fragile
    return g.node("Concat", ins, axis=eqn.params["dimension"]) if len(ins) > 1 else ins[0]


def _stack(g: _Graph, eqn, ins):
    axis = eqn.params["axis"]
    return g.node("Concat", [g.node("Unsqueeze", [x, _i64([axis])]) for x in ins], axis=axis)


def _split(g: _Graph, eqn, ins):
    sizes = eqn.params["sizes"]
    return g.node("Split", [ins[0], _i64(sizes)], outputs=len(sizes), axis=eqn.params["axis"])


def _reduce(g: _Graph, eqn, ins):
    op = {"reduce_sum": "ReduceSum", "reduce_max": "ReduceMax", "reduce_min": "ReduceMin"}[eqn.primitive.name]
    dtype = eqn.invars[0].aval.dtype
    x = ins[0]
    if dtype == np.bool_ or dtype in _NARROW_INTS:
        x = g.node("Cast", [x], to=_onnx_dtype(np.int32))
    out = g.node(op, [x, _i64(eqn.params["axes"])], keepdims=0)
    return out if x is ins[0] else g.node("Cast", [out], to=_onnx_dtype(dtype))


def _arg_reduce(g: _Graph, eqn, ins):
    (axis,) = eqn.params["axes"]
    op = "ArgMin" if eqn.primitive.name == "argmin" else "ArgMax"
    return g.node("Cast", [g.node(op, ins, axis=axis, keepdims=0)], to=_onnx_dtype(eqn.params["index_dtype"]))


def _cumulative(g: _Graph, eqn, ins):
    return g.node("CumSum", [ins[0], _i64(eqn.params["axis"])], reverse=int(eqn.params["reverse"]))


# ---- convolution, windows, gathers, products ----

def _conv(g: _Graph, eqn, ins):
    p = eqn.params
    if any(d != 1 for d in p["lhs_dilation"]) or p["batch_group_count"] != 1:
        raise NotImplementedError("conv_general_dilated with lhs_dilation or batch_group_count (a transposed conv)")
    lhs_spec, rhs_spec, out_spec = p["dimension_numbers"]
    lhs, rhs = ins
    lhs = g.node("Transpose", [lhs], perm=list(lhs_spec))  # -> (N, C, spatial...)
    rhs = np.transpose(rhs, rhs_spec) if not isinstance(rhs, str) else g.node("Transpose", [rhs], perm=list(rhs_spec))
    pads = [lo for lo, _ in p["padding"]] + [hi for _, hi in p["padding"]]
    if min(pads) < 0:
        raise NotImplementedError("conv_general_dilated with negative padding")
    out = g.node("Conv", [lhs, rhs], strides=list(p["window_strides"]), pads=pads,
                 dilations=list(p["rhs_dilation"]), group=p["feature_group_count"])
    return g.node("Transpose", [out], perm=[int(i) for i in np.argsort(out_spec)])


def _reduce_window(g: _Graph, eqn, ins):
    """max / min / sum over a window as the max / min / sum of its shifted, strided slices of the padded operand."""
    p = eqn.params
    if any(d != 1 for d in p["base_dilation"]):
        raise NotImplementedError("reduce_window with base_dilation")
    aval = eqn.invars[0].aval
    kind = eqn.primitive.name.removeprefix("reduce_window_")
    identity = {"max": -np.inf, "min": np.inf, "sum": 0}[kind]
    if np.issubdtype(aval.dtype, np.integer):
        info = np.iinfo(aval.dtype)
        identity = {"max": info.min, "min": info.max, "sum": 0}[kind]
    x = ins[0]
    if any(lo or hi for lo, hi in p["padding"]):
        pads = [lo for lo, _ in p["padding"]] + [hi for _, hi in p["padding"]]
        x = g.node("Pad", [x, _i64(pads), np.asarray(identity, aval.dtype)], mode="constant")
    if aval.dtype in _NARROW_INTS:
        x = g.node("Cast", [x], to=_onnx_dtype(np.int32))
    out_shape = _shape_of(eqn)
    axes = range(len(out_shape))
    terms = []
    for offset in itertools.product(*(range(k) for k in p["window_dimensions"])):
        starts = [o * d for o, d in zip(offset, p["window_dilation"])]
        ends = [s + (n - 1) * st + 1 for s, n, st in zip(starts, out_shape, p["window_strides"])]
        terms.append(g.node("Slice", [x, _i64(starts), _i64(ends), _i64(axes), _i64(p["window_strides"])]))
    out = g.node({"max": "Max", "min": "Min", "sum": "Sum"}[kind], terms) if len(terms) > 1 else terms[0]
    return out if aval.dtype not in _NARROW_INTS else g.node("Cast", [out], to=_onnx_dtype(aval.dtype))


def _gather(g: _Graph, eqn, ins):
    """The gather of jnp.take(x, indices, axis) (one collapsed axis, full slices elsewhere) as ONNX Gather."""
    dn, sizes = eqn.params["dimension_numbers"], eqn.params["slice_sizes"]
    shape, idx_shape = eqn.invars[0].aval.shape, eqn.invars[1].aval.shape
    take = (len(dn.start_index_map) == 1 and tuple(dn.collapsed_slice_dims) == tuple(dn.start_index_map)
            and not dn.operand_batching_dims and idx_shape[-1:] == (1,))
    axis = dn.start_index_map[0] if take else -1
    if not take or any(s != (1 if a == axis else n) for a, (s, n) in enumerate(zip(sizes, shape))):
        raise NotImplementedError(f"gather other than jnp.take along one axis: {dn}")
    out_shape = shape[:axis] + idx_shape[:-1] + shape[axis + 1:]
    if out_shape != _shape_of(eqn):
        raise NotImplementedError(f"gather other than jnp.take along one axis: {dn}")
    indices = ins[1]
    if isinstance(indices, str):
        indices = g.node("Reshape", [indices, _i64(idx_shape[:-1])])
    elif not ((indices >= 0) & (indices < shape[axis])).all():
        raise NotImplementedError("gather with out-of-range constant indices")
    else:
        indices = indices.reshape(idx_shape[:-1]).astype(np.int64)
    return g.node("Gather", [ins[0], indices], axis=axis)


def _dot_general(g: _Graph, eqn, ins):
    (lc, rc), (lb, rb) = eqn.params["dimension_numbers"]
    letters = iter("abcdefghijklmnopqrstuvwxyz")
    lhs = [next(letters) for _ in eqn.invars[0].aval.shape]
    rhs = [next(letters) for _ in eqn.invars[1].aval.shape]
    for i, j in zip(tuple(lc) + tuple(lb), tuple(rc) + tuple(rb)):
        rhs[j] = lhs[i]
    batch = [lhs[i] for i in lb]
    free_l = [c for i, c in enumerate(lhs) if i not in lc and i not in lb]
    free_r = [c for j, c in enumerate(rhs) if j not in rc and j not in rb]
    spec = f"{''.join(lhs)},{''.join(rhs)}->{''.join(batch + free_l + free_r)}"
    out = g.node("Einsum", ins, equation=spec)
    dtype = eqn.outvars[0].aval.dtype
    return out if dtype == eqn.invars[0].aval.dtype else g.node("Cast", [out], to=_onnx_dtype(dtype))


Handler = Callable[[_Graph, jcore.JaxprEqn, list], object]
PRIMITIVES: dict[str, Handler] = {
    **{name: _binary for name in _BINARY}, **{name: _unary for name in _UNARY},
    **{name: _logical for name in ("and", "or", "xor", "not")},
    "ne": _ne, "rsqrt": _rsqrt, "square": _square, "log1p": _log1p, "integer_pow": _integer_pow, "round": _round,
    "is_finite": _is_finite,
    "convert_element_type": _convert, "select_n": _select_n, "clamp": _clamp,
    "reshape": _reshape, "squeeze": _reshape, "expand_dims": _reshape, "broadcast_in_dim": _broadcast_in_dim,
    "transpose": _transpose, "slice": _slice, "rev": _rev, "pad": _pad, "concatenate": _concatenate,
    "stack": _stack, "split": _split, "reduce_sum": _reduce, "reduce_max": _reduce, "reduce_min": _reduce,
    "argmin": _arg_reduce, "argmax": _arg_reduce, "cumsum": _cumulative,
    "conv_general_dilated": _conv, "reduce_window_max": _reduce_window, "reduce_window_min": _reduce_window,
    "reduce_window_sum": _reduce_window, "gather": _gather, "dot_general": _dot_general,
}
"""The primitives `convert` translates, by name (nested jaxprs and scan are handled by `_equation`)."""

_CALLS = ("jit", "pjit", "closed_call", "core_call", "remat", "checkpoint", "custom_jvp_call", "custom_vjp_call",
          "custom_vjp_call_jaxpr")


def _literal(v):
    return np.asarray(v.val, v.aval.dtype)


def _run(g: _Graph, jaxpr: jcore.Jaxpr, consts: Sequence, args: Sequence) -> list:
    """Translates `jaxpr` with its constvars and invars bound to `consts` and `args` (names or arrays)."""
    env = dict(zip(jaxpr.constvars, consts)) | dict(zip(jaxpr.invars, args))

    def read(v):
        return _literal(v) if isinstance(v, jcore.Literal) else env[v]

    for eqn in jaxpr.eqns:
        outs = _equation(g, eqn, [read(v) for v in eqn.invars])
        for var, out in zip(eqn.outvars, outs):
            if not isinstance(var, jcore.DropVar):
                env[var] = out
                if isinstance(out, str):
                    g.value_info.setdefault(out, _value_info(out, var.aval))
    return [read(v) for v in jaxpr.outvars]


def _inner(params) -> jcore.ClosedJaxpr:
    for key in ("jaxpr", "call_jaxpr", "fun_jaxpr"):
        if key in params:
            inner = params[key]
            return inner if isinstance(inner, jcore.ClosedJaxpr) else jcore.ClosedJaxpr(inner, ())
    raise NotImplementedError(f"a call primitive without a jaxpr: {sorted(params)}")


def _scan(g: _Graph, eqn, ins) -> list:
    """An unrolled scan: the body once per step, on step i's slice of each xs; ys stacked at the end."""
    p = eqn.params
    body, n_consts, n_carry = p["jaxpr"], p["num_consts"], p["num_carry"]
    consts, carry, xs = ins[:n_consts], ins[n_consts:n_consts + n_carry], ins[n_consts + n_carry:]
    ys_steps = []
    order = range(p["length"] - 1, -1, -1) if p["reverse"] else range(p["length"])
    for i in order:
        x_i = [x[i] if not isinstance(x, str) else
               g.node("Squeeze", [g.node("Slice", [x, _i64([i]), _i64([i + 1]), _i64([0])]), _i64([0])]) for x in xs]
        outs = _run(g, body.jaxpr, body.consts, list(consts) + list(carry) + x_i)
        carry, ys = outs[:n_carry], outs[n_carry:]
        ys_steps.append(ys)
    if p["reverse"]:
        ys_steps.reverse()
    stacked = []
    for ys in zip(*ys_steps):
        if all(not isinstance(y, str) for y in ys):
            stacked.append(np.stack(ys))
        else:
            stacked.append(g.node("Concat", [g.node("Unsqueeze", [y, _i64([0])]) for y in ys], axis=0))
    return list(carry) + stacked


def _fold(eqn, ins) -> list | None:
    """The outputs of an equation whose inputs are all known, computed now; None when it should stay in the graph
    (an output much larger than its inputs, e.g. a broadcast to an image: cheaper to compute than to store)."""
    if any(isinstance(x, str) for x in ins):
        return None
    largest = max([np.size(x) for x in ins], default=0)
    if any(np.prod(v.aval.shape, dtype=np.int64) > max(FOLD_MAX_ELEMENTS, largest) for v in eqn.outvars):
        return None
    outs = eqn.primitive.bind(*ins, **eqn.params)
    return [np.asarray(o) for o in (outs if eqn.primitive.multiple_results else [outs])]


def _equation(g: _Graph, eqn, ins) -> list:
    name = eqn.primitive.name
    if name in _CALLS:
        inner = _inner(eqn.params)
        return _run(g, inner.jaxpr, inner.consts, ins)
    if name == "scan":
        return _scan(g, eqn, ins)
    if all(0 in v.aval.shape for v in eqn.outvars):  # empty results are known without computing them
        return [np.zeros(v.aval.shape, v.aval.dtype) for v in eqn.outvars]
    folded = _fold(eqn, ins)
    if folded is not None:
        return folded
    if name not in PRIMITIVES:
        raise NotImplementedError(f"jax primitive {name!r} has no ONNX translation in lipjax.jaxpr_to_onnx yet; "
                                  "add one to PRIMITIVES")
    out = PRIMITIVES[name](g, eqn, ins)
    return out if isinstance(out, list) else [out]


def convert(fn: Callable, specs: Sequence[jax.ShapeDtypeStruct], input_names: Sequence[str],
            output_names: Sequence[str], metadata: dict[str, str] | None = None, doc: str = ""):
    """The ONNX ModelProto (opset OPSET) of `fn(*inputs) -> output or tuple of outputs` for inputs of `specs`.

    Constants `fn` closes over (parameters) become initializers; every shape is static."""
    import onnx
    import onnx.helper

    closed = jax.make_jaxpr(fn)(*specs)
    g = _Graph()
    outs = _run(g, closed.jaxpr, [np.asarray(c) for c in closed.consts], list(input_names))
    if len(outs) != len(output_names):
        raise ValueError(f"the function returns {len(outs)} outputs; got {len(output_names)} output names")
    for out, name in zip(outs, output_names):
        g.nodes.append(onnx.helper.make_node("Identity", [g.tensor(out)], [name]))

    graph = onnx.helper.make_graph(
        g.nodes, "lipjax", [_value_info(n, v.aval) for n, v in zip(input_names, closed.jaxpr.invars)],
        [_value_info(n, v.aval) for n, v in zip(output_names, closed.jaxpr.outvars)], initializer=g.initializers,
        value_info=[v for name, v in g.value_info.items() if name not in (*input_names, *output_names)])
    model = onnx.helper.make_model(graph, opset_imports=[onnx.helper.make_opsetid("", OPSET)],
                                   producer_name="lipjax", doc_string=doc)
    onnx.helper.set_model_props(model, dict(metadata or {}))
    onnx.checker.check_model(model)
    return model
