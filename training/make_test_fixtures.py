"""Writes the small, deliberately incompatible ONNX models the Rust tests load.

    python training/make_test_fixtures.py [--out tests/fixtures]

Each model is valid ONNX but breaks one part of the PR model contract
(``crates/primm-predictor/src/onnx/contract.rs``), so loading it must fail with a start-up error naming the problem:

* ``pr_wrong_feature_shape.onnx``: ``features`` is ``[batch, 4, 5]`` (four history rows);
* ``pr_fixed_batch.onnx``: ``features`` is ``[1, 5, 5]`` (no symbolic batch axis);
* ``pr_wrong_output_shape.onnx``: ``displacement`` is ``[batch, 3]``;
* ``pr_missing_valid_input.onnx``: only the ``features`` input;
* ``pr_unknown_input_frame.onnx``: a conforming model whose ``primm.input_frame`` metadata entry
  names no input frame (``sideways``).

Two more keep the contract, so that the tests can see which input axes primm rotates a request
into: ``pr_latest_motion.onnx`` (no ``primm.input_frame`` entry, as the models trained before the
line of sight) and ``pr_line_of_sight.onnx`` (the entry ``line_of_sight``). Their displacement is
``0.1 ·`` the sum of all valid features, on both axes.

Only the ``onnx`` package is needed (no PyTorch).
"""

from __future__ import annotations

import argparse
import os

import numpy as np
import onnx
from onnx import TensorProto, helper, numpy_helper

OPSET = 17


def model(name: str, features_shape, valid: bool, outputs: int, input_frame: str | None = None) -> onnx.ModelProto:
    """features -> sum over the history rows -> [batch, 5] @ W[5, outputs] -> displacement."""
    batch = features_shape[0]
    inputs = [helper.make_tensor_value_info("features", TensorProto.FLOAT, features_shape)]
    if valid:
        inputs.append(helper.make_tensor_value_info("valid", TensorProto.FLOAT, [batch, 5]))
    weight = numpy_helper.from_array(np.full((features_shape[2], outputs), 0.1, np.float32), "weight")
    axes = numpy_helper.from_array(np.array([1], np.int64), "axes")
    nodes = [
        helper.make_node("ReduceSum", ["features", "axes"], ["summed"], keepdims=0),
        helper.make_node("MatMul", ["summed", "weight"], ["displacement"]),
    ]
    output = helper.make_tensor_value_info("displacement", TensorProto.FLOAT, [batch, outputs])
    graph = helper.make_graph(nodes, name, inputs, [output], initializer=[weight, axes])
    result = helper.make_model(graph, opset_imports=[helper.make_opsetid("", OPSET)], producer_name="primm-fixtures")
    result.ir_version = 8
    if input_frame is not None:
        helper.set_model_props(result, {"primm.input_frame": input_frame})
    onnx.checker.check_model(result, full_check=True)
    return result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", default=os.path.join("tests", "fixtures"))
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)
    fixtures = {
        "pr_wrong_feature_shape.onnx": model("wrong_feature_shape", ["batch", 4, 5], True, 2),
        "pr_fixed_batch.onnx": model("fixed_batch", [1, 5, 5], True, 2),
        "pr_wrong_output_shape.onnx": model("wrong_output_shape", ["batch", 5, 5], True, 3),
        "pr_missing_valid_input.onnx": model("missing_valid_input", ["batch", 5, 5], False, 2),
        "pr_unknown_input_frame.onnx": model("unknown_input_frame", ["batch", 5, 5], True, 2, "sideways"),
        "pr_latest_motion.onnx": model("latest_motion", ["batch", 5, 5], True, 2),
        "pr_line_of_sight.onnx": model("line_of_sight", ["batch", 5, 5], True, 2, "line_of_sight"),
    }
    for name, proto in fixtures.items():
        path = os.path.join(args.out, name)
        onnx.save(proto, path)
        print(f"wrote {path} ({os.path.getsize(path)} bytes)")


if __name__ == "__main__":
    main()
