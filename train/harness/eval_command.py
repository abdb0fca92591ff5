"""``homing-eval``: score one method on a suite of seeded episodes, or on a protocol.

    homing-eval --policy oracle --env homing_gym/LocalHoming-v0 --episodes 200 --seed 0 \\
        --workers 2 --out results/oracle.json
    homing-eval --protocol yukim --policy distance --out results/yukim_distance.json

With ``--protocol NAME`` (:mod:`homing_train.harness.protocols`) the protocol fixes the
envs, env kwargs, episodes and the success rule (stop within the radius); ``--episodes``
then counts per setting (default: the protocol's), ``--seed S`` draws the protocol's
episodes from base seed ``S`` instead of its own (recorded as ``"canonical_draw": false``
and said in the summary), each setting's results go to the folder ``NAME`` beside
``--out`` (without its extension) and ``--out`` gets the cell: the summary over all
settings.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from pathlib import Path

from homing_gym.cli import command_parser, env_kwargs_from_args
from homing_train.harness.evaluate import (DEFAULT_ENV, add_backend_arguments,
                                           add_policy_arguments, evaluate,
                                           format_summary, policy_from_args, stream_path)
from homing_train.harness.matrix import run_cell
from homing_train.harness.policies import recorded_settings
from homing_train.harness.protocols import PROTOCOLS, protocol


def _protocol_cell(args) -> int:
    """``--protocol``: run the cell and print its summary."""
    if args.env != DEFAULT_ENV or args.env_kwargs or args.scene or args.param:
        raise ValueError("--protocol fixes the env, its kwargs and the method's parameters; "
                         "drop --env/--env-kwargs/--scene/--param")
    chosen = protocol(args.protocol)
    if args.seed is not None:
        chosen = chosen.reseeded(args.seed)
    folder = Path(os.path.splitext(args.out)[0])
    if folder == Path(args.out):        # the cell's file and its settings' folder would clash
        raise ValueError(f"--out {args.out!r} needs an extension with --protocol, e.g. "
                         f"{args.out}.json: the settings' results go to the folder {args.out}/")
    cell = run_cell(chosen, args.policy, folder, args.episodes, args.workers,
                    progress=not args.quiet, resume=args.resume, backend=args.backend,
                    address=args.ray_address)
    shutil.copyfile(folder / "cell.json", args.out)
    s = cell.summary
    print(f"{args.policy} on {chosen.label}: {s['episodes']} episodes, success (stopped "
          f"within the radius) {100 * s['success_rate']:.1f}% "
          f"[{100 * s['success_ci'][0]:.1f}, {100 * s['success_ci'][1]:.1f}], reached "
          f"{100 * s['reached_rate']:.1f}%, SPL {s['spl']:.3f}; by setting "
          f"{json.dumps(cell.settings)}")
    print(f"wrote {args.out} and the settings' results in {folder}/")
    return 0


def main(argv: list[str] | None = None) -> int:
    parser = command_parser("homing-eval", __doc__)
    add_policy_arguments(parser)
    parser.add_argument("--protocol", choices=sorted(PROTOCOLS),
                        help="run the method on this protocol (see the module help)")
    parser.add_argument("--episodes", type=int, default=None,
                        help="episodes (default 100; with --protocol: per setting, default "
                        "the protocol's)")
    parser.add_argument("--bin-width", type=float, default=0.3,
                        help="start-distance bin width (m) for success by distance")
    parser.add_argument("--out", required=True,
                        help="result JSON path (a .csv goes beside; each finished episode is "
                        "appended to NAME.episodes.jsonl as it ends)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the episodes already in NAME.episodes.jsonl and run the rest")
    add_backend_arguments(parser)
    args = parser.parse_args(argv)
    try:
        for path in (args.out, stream_path(args.out)):
            if os.path.isdir(path):
                raise ValueError(f"--out {path!r} is a directory")
        if args.protocol:
            return _protocol_cell(args)
        spec = policy_from_args(args)
        result = evaluate(spec, args.env, 100 if args.episodes is None else args.episodes,
                          args.seed or 0, env_kwargs_from_args(args), args.workers,
                          bin_width=args.bin_width, progress=not args.quiet,
                          stream=stream_path(args.out), resume=args.resume,
                          backend=args.backend, address=args.ray_address)
    except ValueError as err:
        parser.exit(2, f"homing-eval: error: {err}\n")
    except KeyboardInterrupt:
        parser.exit(130, f"homing-eval: interrupted; the finished episodes are in "
                         f"{stream_path(args.out)}: the same command with --resume runs "
                         f"the rest\n")
    result.save(args.out)
    if spec.kind == "sb3" and (recorded := recorded_settings(spec.source)).source:
        print(f"settings recorded in {recorded.source} (explicit --env-kwargs/--param "
              f"override them): env kwargs {result.env_kwargs}, params {result.params}")
    print(format_summary(result))
    print(f"wrote {args.out} and {os.path.splitext(args.out)[0]}.csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
