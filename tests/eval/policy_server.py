#!/usr/bin/python3
"""A test stand-in for openpi's websocket policy server (Debian python3-websockets
10.4 and python3-msgpack). Like openpi's server it sends a metadata map on
connect, answers each msgpack observation with {"actions": ndarray (H, 7)},
and on an exception sends the traceback as a text frame and closes with 1011.
numpy arrays travel as openpi-client's msgpack_numpy encodes them: maps with
binary keys __ndarray__, data, dtype, shape.

It checks every field the client sends (keys, key types, dtypes, shapes, the
180-degree rotation is not checkable here, but padding/size are) and fails
loudly otherwise. Modes make it misbehave for the client's error paths;
--declare-thermal and --image-keys add what hearth's openpi adapter declares
to the metadata.
"""
import argparse
import asyncio
import json
import os
import sys
import traceback

import msgpack
import numpy as np
import websockets

ND_KEYS = {b"__ndarray__", b"data", b"dtype", b"shape"}


def unpack_array(obj):
    # strict: ndarray maps must use binary keys exactly
    if b"__ndarray__" in obj:
        if set(obj.keys()) != ND_KEYS:
            raise ValueError("ndarray map keys %r" % (sorted(obj.keys()),))
        if obj[b"__ndarray__"] is not True:
            raise ValueError("__ndarray__ is not True")
        if not isinstance(obj[b"data"], bytes) or not isinstance(obj[b"dtype"], str):
            raise ValueError("ndarray data must be bin and dtype str")
        return np.ndarray(buffer=obj[b"data"], dtype=np.dtype(obj[b"dtype"]), shape=obj[b"shape"])
    if "__ndarray__" in obj:
        raise ValueError("ndarray keys must be binary, got str")
    return obj


def pack_array(obj):
    if isinstance(obj, np.ndarray):
        return {b"__ndarray__": True, b"data": obj.tobytes(), b"dtype": obj.dtype.str, b"shape": obj.shape}
    return obj


def check_obs(obs, args):
    if not isinstance(obs, dict):
        raise ValueError("observation is not a map")
    want = {"observation/image", "observation/wrist_image", "observation/state", "prompt"}
    if args.thermal:
        want.add("observation/thermal_image")
    if set(obs.keys()) != want:
        raise ValueError("observation keys %r, expected %r" % (sorted(obs.keys()), sorted(want)))
    for k in ("observation/image", "observation/wrist_image", "observation/thermal_image"):
        if k not in obs:
            continue
        im = obs[k]
        if not isinstance(im, np.ndarray) or im.dtype != np.uint8 or im.shape != (args.size, args.size, 3):
            raise ValueError("%s: expected uint8 (%d, %d, 3), got %r %r" % (
                k, args.size, args.size, getattr(im, "dtype", None), getattr(im, "shape", None)))
        if im.max() == 0:
            raise ValueError("%s: all black" % k)
    st = obs["observation/state"]
    if not isinstance(st, np.ndarray) or st.dtype.kind != "f" or st.shape != (8,):
        raise ValueError("observation/state: expected float (8,), got %r" % (st,))
    if not np.all(np.isfinite(st)) or not (0.5 < st[2] < 2.0):
        raise ValueError("observation/state: implausible %r" % (st,))
    if not isinstance(obs["prompt"], str) or "the mat" not in obs["prompt"]:
        raise ValueError("prompt: %r" % (obs["prompt"],))


async def handler(ws, path, args, state):
    state["connections"] += 1
    conn = state["connections"]
    meta = {"server": "hearth-test", "action_horizon": args.horizon, "shape": np.array([args.horizon, 7])}
    # what hearth's openpi adapter declares; a stock server declares nothing
    if args.declare_thermal != "none":
        meta["hearth_thermal"] = args.declare_thermal == "true"
    if args.image_keys is not None:
        meta["image_keys"] = [k for k in args.image_keys.split(",") if k]
    await ws.send(msgpack.packb(meta, default=pack_array))
    nreq = 0
    try:
        while True:
            msg = await ws.recv()
            if not isinstance(msg, bytes):
                raise ValueError("request is not a binary frame")
            obs = msgpack.unpackb(msg, object_hook=unpack_array)
            check_obs(obs, args)
            nreq += 1
            state["requests"] += 1
            with open(args.log, "a") as f:
                f.write(json.dumps({"conn": conn, "req": nreq, "prompt": obs["prompt"],
                                    "state": [float(x) for x in obs["observation/state"]]}) + "\n")
            bad = (args.bad_at == 0 or nreq == args.bad_at) and (args.bad_conn == 0 or conn == args.bad_conn)
            if bad and args.mode == "disconnect":
                ws.transport.abort()
                return
            if bad and args.mode == "garbage":
                await ws.send(b"\xc1 this is not msgpack")
                continue
            if bad and args.mode == "rawgarbage":
                ws.transport.write(b"\xff\xfe\xfd garbage on the wire")
                continue
            if bad and args.mode == "slow":
                await asyncio.sleep(args.sleep)
            if bad and args.mode == "error":
                raise RuntimeError("policy exploded on purpose")
            if bad and args.mode == "short":
                actions = np.zeros((2, 7), np.float32)
            elif bad and args.mode == "nan":
                actions = np.full((args.horizon, 7), np.nan, np.float32)
            elif bad and args.mode == "wide":
                actions = np.zeros((args.horizon, 6), np.float32)
            elif args.actions:
                # serve a recorded trajectory: the chunk starting at this step
                acts = state["actions"][obs["prompt"]]
                if state.get("prompt") != obs["prompt"] or state.get("conn") != conn:
                    state["prompt"], state["conn"], state["base"] = obs["prompt"], conn, nreq - 1
                t0 = (nreq - 1 - state["base"]) * args.replan
                chunk = acts[t0:t0 + args.horizon]
                if len(chunk) < args.horizon:
                    pad = np.tile(np.array([[0, 0, 0, 0, 0, 0, -1]], acts.dtype), (args.horizon - len(chunk), 1))
                    chunk = np.concatenate([chunk, pad]) if len(chunk) else pad
                actions = chunk  # the stored dtype (<f8): bit-exact open-loop replay
            else:
                actions = np.tile(np.array([[0, 0, 0, 0, 0, 0, -1]], np.float32), (args.horizon, 1))
            await ws.send(msgpack.packb({"actions": actions, "server_timing": {"infer_ms": 1.0}},
                                        default=pack_array))
    except websockets.ConnectionClosed:
        return
    except Exception:
        await ws.send(traceback.format_exc())
        await ws.close(code=1011, reason="Internal server error. Traceback included in previous frame.")


async def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--port-file", required=True)
    ap.add_argument("--log", required=True)
    ap.add_argument("--size", type=int, default=224)
    ap.add_argument("--thermal", type=int, default=1)
    ap.add_argument("--horizon", type=int, default=10)
    ap.add_argument("--replan", type=int, default=5)
    ap.add_argument("--mode", default="ok")
    ap.add_argument("--bad-at", type=int, default=2, help="the request that goes wrong; 0: every one")
    ap.add_argument("--declare-thermal", choices=["none", "true", "false"], default="none",
                    help="metadata hearth_thermal (none: the key is left out)")
    ap.add_argument("--image-keys", default=None, help="metadata image_keys, comma-separated")
    ap.add_argument("--bad-conn", type=int, default=1)
    ap.add_argument("--sleep", type=float, default=3.0)
    ap.add_argument("--actions", default="")
    args = ap.parse_args()
    state = {"connections": 0, "requests": 0}
    if args.actions:
        # the demos of a `hearth sim collect` file, by instruction
        import h5py
        state["actions"] = {}
        with h5py.File(args.actions, "r") as f:
            for name in f["data"]:
                g = f["data"][name]
                ins = g.attrs["language_instruction"]
                ins = ins.decode() if isinstance(ins, bytes) else str(ins)
                state["actions"].setdefault(ins, np.array(g["actions"]))
    async with websockets.serve(lambda ws, path: handler(ws, path, args, state), "127.0.0.1", 0,
                                compression=None, max_size=None) as server:
        port = server.sockets[0].getsockname()[1]
        tmp = args.port_file + ".tmp"
        with open(tmp, "w") as f:
            f.write(str(port))
        os.rename(tmp, args.port_file)
        await asyncio.Future()


if __name__ == "__main__":
    try:
        asyncio.run(main())
    except KeyboardInterrupt:
        sys.exit(0)
