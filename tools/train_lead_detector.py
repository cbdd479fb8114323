#!/usr/bin/python3
"""Trains Wingman's learned lead detector and exports it to ONNX for OpenCV's dnn module.

The network is a small fully convolutional CenterNet-style keypoint head on grey images: from an
H x W image (0-255, any size divisible by 4) it gives three H/4 x W/4 maps, the probability that
x_h's projection lies in each 4 x 4 cell and the position of x_h inside the cell (x, y in [0, 1)):
u = 4 (column + x) - 0.5, v = 4 (row + y) - 0.5 (pixel centres at integers). Training data are
`wingman render` datasets with cam0_lead0 labels (tools/lead_data.py): crops around the lead and
crops without it, turned, mirrored, rescaled and with noise, blur, brightness and contrast drawn
per sample. Datasets whose ground is held out score the detector on crops it never saw.

  tools/train_lead_detector.py --data DIR [--data DIR ...] --hold-out site --out assets/lead/lead_detector.onnx
                               [--epochs 30] [--minutes 25] [--width 32] [--seed 1] [--threads 2]

Writes the ONNX file and, beside it, <name>.json: the command, the datasets, the seeds, the
training time and the held-out metrics. Runs on CPU (Debian's python3-torch)."""
import argparse
import csv
import glob
import json
import math
import os
import platform
import sys
import time

import cv2
import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F

CROP = 128  # training crops, px
REGION = 192  # what is kept of a frame around each crop's centre, px
STRIDE = 4


def conv(i, o, stride=1, dilation=1):
    return [nn.Conv2d(i, o, 3, stride, padding=dilation, dilation=dilation, bias=False), nn.BatchNorm2d(o),
            nn.ReLU(inplace=True)]


class LeadNet(nn.Module):
    def __init__(self, width=32):
        super().__init__()
        w = width
        self.body = nn.Sequential(*conv(1, w // 2, 2), *conv(w // 2, w), *conv(w, w, 2), *conv(w, 2 * w),
                                  *conv(2 * w, 2 * w, 1, 2), *conv(2 * w, 2 * w, 1, 4), *conv(2 * w, 2 * w, 1, 8),
                                  *conv(2 * w, 2 * w))
        self.head = nn.Conv2d(2 * w, 3, 1)
        nn.init.constant_(self.head.bias, 0.0)
        with torch.no_grad():
            self.head.bias[0] = -4.6  # start at p = 0.01: most cells hold no lead

    def forward(self, x):
        return torch.sigmoid(self.head(self.body((x - 127.5) / 64.0)))


def read_dataset(root):
    """Every frame of every UAV with its label: (image path, u, v, visible, box)."""
    out = []
    for lead_csv in sorted(glob.glob(os.path.join(root, "*", "mav0", "cam0_lead0", "data.csv"))):
        mav0 = os.path.dirname(os.path.dirname(lead_csv))
        with open(lead_csv) as f:
            for row in csv.reader(f):
                if row[0].startswith("#"):
                    continue
                t = row[0]
                out.append(dict(image=os.path.join(mav0, "cam0", "data", t + ".png"), u=float(row[1]),
                                v=float(row[2]), visible=float(row[4]), box=[int(x) for x in row[5:9]]))
    if not out:
        sys.exit(f"train_lead_detector: {root}: no cam0_lead0/data.csv under it (render it with tools/lead_data.py)")
    return out


def region(img, cx, cy):
    """The REGION x REGION square centred on (cx, cy), zero outside the image, and its top-left."""
    x0, y0 = int(round(cx)) - REGION // 2, int(round(cy)) - REGION // 2
    out = np.zeros((REGION, REGION), np.uint8)
    sx0, sy0 = max(0, x0), max(0, y0)
    sx1, sy1 = min(img.shape[1], x0 + REGION), min(img.shape[0], y0 + REGION)
    if sx1 > sx0 and sy1 > sy0:
        out[sy0 - y0:sy1 - y0, sx0 - x0:sx1 - x0] = img[sy0:sy1, sx0:sx1]
    return out, x0, y0


def load_samples(frames, rng, min_visible):
    """Per frame: a region around the lead (a positive) and one away from it (a negative)."""
    pos, neg = [], []
    for fr in frames:
        img = cv2.imread(fr["image"], cv2.IMREAD_GRAYSCALE)
        if img is None:
            sys.exit(f"train_lead_detector: {fr['image']}: cannot read the frame")
        h, w = img.shape
        if fr["visible"] >= min_visible and 0 <= fr["u"] < w and 0 <= fr["v"] < h:
            r, x0, y0 = region(img, fr["u"], fr["v"])
            pos.append((r, fr["u"] - x0, fr["v"] - y0))
        b = fr["box"]
        for _ in range(20):  # a region whose central crop misses the lead's box by a margin
            cx, cy = rng.uniform(CROP / 2, w - CROP / 2), rng.uniform(CROP / 2, h - CROP / 2)
            if b[2] <= b[0] or cx + CROP / 2 + 8 < b[0] or cx - CROP / 2 - 8 > b[2] or \
                    cy + CROP / 2 + 8 < b[1] or cy - CROP / 2 - 8 > b[3]:
                r, _, _ = region(img, cx, cy)
                neg.append(r)
                break
    return pos, neg


def augment(r, uv, rng):
    """A CROP x CROP crop of region r (the lead at uv, or none), rescaled, turned, mirrored, with
    the camera's nuisances; returns the crop and the lead's position in it (or None)."""
    s = rng.uniform(0.75, 1.3)
    size = int(round(REGION * s))
    img = cv2.resize(r, (size, size), interpolation=cv2.INTER_AREA if s < 1 else cv2.INTER_LINEAR)
    # A pixel centre c of the region is at (c + 0.5) s - 0.5 after resizing.
    if uv is not None:
        u, v = (uv[0] + 0.5) * s - 0.5, (uv[1] + 0.5) * s - 0.5
        lo, hi = 6, CROP - 7
        x0 = int(np.clip(round(u - rng.uniform(lo, hi)), 0, size - CROP))
        y0 = int(np.clip(round(v - rng.uniform(lo, hi)), 0, size - CROP))
        uv = [u - x0, v - y0]
    else:
        x0 = rng.integers(0, size - CROP + 1)
        y0 = rng.integers(0, size - CROP + 1)
    c = img[y0:y0 + CROP, x0:x0 + CROP].astype(np.float32)
    k = int(rng.integers(0, 4))
    c = np.rot90(c, k)  # counter-clockwise: (u, v) -> (v, W - 1 - u)
    if uv is not None:
        for _ in range(k):
            uv = [uv[1], CROP - 1 - uv[0]]
    if rng.random() < 0.5:
        c = c[:, ::-1]
        if uv is not None:
            uv = [CROP - 1 - uv[0], uv[1]]
    c = np.ascontiguousarray(c)
    if rng.random() < 0.3:
        c = cv2.GaussianBlur(c, (0, 0), rng.uniform(0.4, 1.5))
    c = c * rng.uniform(0.6, 1.4) + rng.uniform(-30, 30)
    c = c + rng.normal(0, rng.uniform(0, 6), c.shape)
    return np.clip(c, 0, 255).astype(np.float32), uv


def targets(uv, n):
    """Heat map (a Gaussian of 1 cell around x_h's cell, 1 at it), offsets, and the cell."""
    heat = np.zeros((n, n), np.float32)
    if uv is None:
        return heat, np.zeros(2, np.float32), (-1, -1)
    gx, gy = (uv[0] + 0.5) / STRIDE, (uv[1] + 0.5) / STRIDE
    cx, cy = min(int(gx), n - 1), min(int(gy), n - 1)
    ys, xs = np.mgrid[0:n, 0:n]
    heat = np.exp(-((xs - cx) ** 2 + (ys - cy) ** 2) / 2.0).astype(np.float32)
    return heat, np.array([gx - cx, gy - cy], np.float32), (cy, cx)


def batch(pos, neg, rng, size, neg_share=0.3):
    n = CROP // STRIDE
    xs, heats, offs, cells = [], [], [], []
    for _ in range(size):
        if rng.random() < neg_share:
            c, uv = augment(neg[rng.integers(len(neg))], None, rng)
        else:
            r, u, v = pos[rng.integers(len(pos))]
            c, uv = augment(r, [u, v], rng)
        h, o, cell = targets(uv, n)
        xs.append(c[None])
        heats.append(h)
        offs.append(o)
        cells.append(cell)
    return (torch.from_numpy(np.stack(xs)), torch.from_numpy(np.stack(heats)), torch.from_numpy(np.stack(offs)),
            cells)


def loss_fn(out, heat, offs, cells):
    p = out[:, 0].clamp(1e-4, 1 - 1e-4)
    peak = heat >= 1.0
    pos_loss = -((1 - p) ** 2 * torch.log(p))[peak].sum()
    neg_loss = -((1 - heat) ** 4 * p ** 2 * torch.log(1 - p))[~peak].sum()
    npos = max(1, int(peak.sum()))
    off_loss = out.new_zeros(())
    for i, (cy, cx) in enumerate(cells):
        if cy >= 0:
            off_loss = off_loss + F.l1_loss(out[i, 1:, cy, cx], offs[i], reduction="sum")
    return (pos_loss + neg_loss) / npos + off_loss / npos


def decode(maps):
    """The strongest cell of a 3 x h x w map: (probability, u, v)."""
    heat = maps[0]
    idx = int(np.argmax(heat))
    cy, cx = divmod(idx, heat.shape[1])
    return float(heat[cy, cx]), STRIDE * (cx + maps[1, cy, cx]) - 0.5, STRIDE * (cy + maps[2, cy, cx]) - 0.5


def evaluate(model, pos, neg, rng, threshold):
    """On crops of held-out regions: detection rate (peak above threshold within 4 px), median and
    p95 pixel error of the detections, and false detections on crops without the lead."""
    model.eval()
    errs, hits, false = [], 0, 0
    with torch.no_grad():
        for r, u, v in pos:
            x0 = int(np.clip(round(u - rng.uniform(8, CROP - 9)), 0, REGION - CROP))
            y0 = int(np.clip(round(v - rng.uniform(8, CROP - 9)), 0, REGION - CROP))
            c = r[y0:y0 + CROP, x0:x0 + CROP].astype(np.float32)
            maps = model(torch.from_numpy(c)[None, None])[0].numpy()
            p, pu, pv = decode(maps)
            e = math.hypot(pu - (u - x0), pv - (v - y0))
            if p >= threshold and e <= 4:
                hits += 1
                errs.append(e)
        for r in neg:
            c = r[32:32 + CROP, 32:32 + CROP].astype(np.float32)
            p, _, _ = decode(model(torch.from_numpy(c)[None, None])[0].numpy())
            false += p >= threshold
    model.train()
    errs = np.array(errs)
    return dict(crops_with_lead=len(pos), detection_rate=hits / max(1, len(pos)),
                median_error_px=float(np.median(errs)) if errs.size else None,
                p95_error_px=float(np.percentile(errs, 95)) if errs.size else None,
                crops_without_lead=len(neg), false_detection_rate=false / max(1, len(neg)))


def export(model, path):
    model.eval()
    dummy = torch.zeros(1, 1, CROP, CROP)
    torch.onnx.export(model, dummy, path, opset_version=11, input_names=["image"], output_names=["maps"],
                      dynamic_axes={"image": {2: "height", 3: "width"}, "maps": {2: "rows", 3: "cols"}})
    # OpenCV's dnn must read it and give PyTorch's numbers.
    net = cv2.dnn.readNetFromONNX(path)
    x = np.random.default_rng(0).uniform(0, 255, (1, 1, 160, 224)).astype(np.float32)
    net.setInput(x)
    got = net.forward()
    want = model(torch.from_numpy(x)).detach().numpy()
    if got.shape != want.shape or float(np.abs(got - want).max()) > 1e-4:
        sys.exit(f"train_lead_detector: {path}: OpenCV's output differs from PyTorch's "
                 f"(shape {got.shape} vs {want.shape}, max difference {float(np.abs(got - want).max()):.3g})")
    return float(np.abs(got - want).max())


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data", action="append", required=True, help="a directory of datasets (tools/lead_data.py)")
    ap.add_argument("--hold-out", default="site", help="datasets whose name starts with this ground are held out")
    ap.add_argument("--out", required=True)
    ap.add_argument("--epochs", type=int, default=30)
    ap.add_argument("--steps-per-epoch", type=int, default=100)
    ap.add_argument("--batch", type=int, default=32)
    ap.add_argument("--minutes", type=float, default=25, help="stop after this long, whatever the epoch")
    ap.add_argument("--width", type=int, default=32)
    ap.add_argument("--min-visible", type=float, default=0.8)
    ap.add_argument("--threshold", type=float, default=0.3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    torch.manual_seed(a.seed)
    torch.set_num_threads(a.threads)
    rng = np.random.default_rng(a.seed)
    train_sets, held_sets = [], []
    for d in a.data:
        for ds in sorted(glob.glob(os.path.join(d, "*", "dataset.yaml"))):
            name = os.path.basename(os.path.dirname(ds))
            (held_sets if name.startswith(a.hold_out + "_") else train_sets).append(os.path.dirname(ds))
    if not train_sets:
        sys.exit("train_lead_detector: no training datasets under " + ", ".join(a.data))
    frames = [f for d in train_sets for f in read_dataset(d)]
    held = [f for d in held_sets for f in read_dataset(d)]
    pos, neg = load_samples(frames, rng, a.min_visible)
    hpos, hneg = load_samples(held, rng, a.min_visible)
    if not pos:
        sys.exit("train_lead_detector: no frame shows the lead")
    print(f"train: {len(train_sets)} datasets, {len(pos)} crops with the lead, {len(neg)} without; "
          f"held out: {len(held_sets)} datasets, {len(hpos)} with, {len(hneg)} without", flush=True)
    model = LeadNet(a.width)
    opt = torch.optim.Adam(model.parameters(), lr=2e-3)
    total = a.epochs * a.steps_per_epoch
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=3e-3, total_steps=total, pct_start=0.1)
    start = time.time()
    history = []
    step = 0
    for epoch in range(a.epochs):
        run = 0.0
        for _ in range(a.steps_per_epoch):
            x, heat, offs, cells = batch(pos, neg, rng, a.batch)
            out = model(x)
            loss = loss_fn(out, heat, offs, cells)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            step += 1
            run += float(loss)
        history.append(dict(epoch=epoch + 1, loss=run / a.steps_per_epoch, minutes=(time.time() - start) / 60))
        print(f"epoch {epoch + 1}: loss {run / a.steps_per_epoch:.4f} ({(time.time() - start) / 60:.1f} min)",
              flush=True)
        if time.time() - start > 60 * a.minutes:
            print("train_lead_detector: the time budget is spent", flush=True)
            break
    minutes = (time.time() - start) / 60
    eval_rng = np.random.default_rng(a.seed + 1)
    held_metrics = evaluate(model, hpos, hneg, eval_rng, a.threshold) if hpos else None
    train_metrics = evaluate(model, pos[:500], neg[:500], eval_rng, a.threshold)
    os.makedirs(os.path.dirname(os.path.abspath(a.out)), exist_ok=True)
    tmp = a.out + ".partial"
    diff = export(model, tmp)
    record = dict(
        command=" ".join(["tools/train_lead_detector.py"] + sys.argv[1:]),
        network=dict(kind="LeadNet", width=a.width, stride=STRIDE, input="grey, 0-255, 1 x 1 x H x W (H, W multiples of 4)",
                     output="maps 1 x 3 x H/4 x W/4: p(x_h in cell), x and y of x_h in the cell",
                     parameters=sum(p.numel() for p in model.parameters()), threshold=a.threshold),
        training=dict(datasets=[os.path.basename(d) for d in train_sets], crops_with_lead=len(pos),
                      crops_without_lead=len(neg), epochs=len(history), steps_per_epoch=a.steps_per_epoch,
                      batch=a.batch, seed=a.seed, threads=a.threads, minutes=round(minutes, 2),
                      min_visible=a.min_visible, history=history),
        held_out=dict(ground=a.hold_out, datasets=[os.path.basename(d) for d in held_sets], metrics=held_metrics),
        train_metrics=train_metrics,
        export=dict(opset=11, opencv=cv2.__version__, max_difference_opencv_vs_torch=diff),
        software=dict(python=platform.python_version(), torch=torch.__version__, numpy=np.__version__))
    os.replace(tmp, a.out)
    with open(os.path.splitext(a.out)[0] + ".json", "w") as f:
        json.dump(record, f, indent=1)
    print(json.dumps(dict(held_out=held_metrics, train=train_metrics), indent=1))


if __name__ == "__main__":
    main()
