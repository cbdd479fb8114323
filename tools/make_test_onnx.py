#!/usr/bin/python3
"""Writes tests/data/lead_two_maps.onnx: a fully convolutional network of the lead detector's input
(1 x 1 x H x W) whose output has 2 maps instead of 3, for the test that a weights file of the wrong
shape is refused.   tools/make_test_onnx.py OUT"""
import sys

import torch

net = torch.nn.Sequential(torch.nn.Conv2d(1, 2, 3, 4, padding=1), torch.nn.Sigmoid())
torch.manual_seed(0)
torch.onnx.export(net, torch.zeros(1, 1, 64, 64), sys.argv[1], opset_version=11, input_names=["image"],
                  output_names=["maps"], dynamic_axes={"image": {2: "h", 3: "w"}, "maps": {2: "r", 3: "c"}})
