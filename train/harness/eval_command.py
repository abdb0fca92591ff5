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
import sys
from pathlib import Path

from homing_gym.cli import command_parser, env_kwargs_from_args
from homing_train.harness.evaluate import (DEFAULT_ENV, add_backend_arguments,
                                           add_policy_arguments, check_backend_arguments,
                                           evaluate, format_summary, policy_from_args,
                                           stream_path)
from homing_train.harness.matrix import run_cell
from homing_train.harness.policies import recorded_settings
from homing_train.harness.protocols import PROTOCOLS, protocol
from homing_gym.outputs import (OutputLock, checked_output_dir, checked_output_file,
                                  output_file_argument, write_text_atomic)
from homing_train.pool import WorkerDiedError, end_stopped_command


def _settings_folder(out: str) -> Path:
    """``--protocol``'s folder of the settings' results: ``--out`` without its extension
    (``ValueError`` if it has none, or the folder cannot be written)."""
    folder = os.path.splitext(out)[0]
    if folder == out:                   # the cell's file and its settings' folder would clash
        raise ValueError(f"--out {out!r} needs an extension with --protocol, e.g. "
                         f"{out}.json: the settings' results go to the folder {out}/")
    return Path(checked_output_dir(folder, "--out's settings folder"))


def _protocol_cell(args) -> int:
    """``--protocol``: run the cell and print its summary."""
    if args.env != DEFAULT_ENV or args.env_kwargs or args.scene or args.param:
        raise ValueError("--protocol fixes the env, its kwargs and the method's parameters; "
                         "drop --env/--env-kwargs/--scene/--param")
    chosen = protocol(args.protocol)
    if args.seed is not None:
        chosen = chosen.reseeded(args.seed)
    folder = _settings_folder(args.out)
    cell = run_cell(chosen, args.policy, folder, args.episodes, args.workers,
                    progress=not args.quiet, resume=args.resume, backend=args.backend,
                    address=args.ray_address)
    write_text_atomic(args.out, (folder / "cell.json").read_text())
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
    parser.add_argument("--out", required=True, type=output_file_argument,
                        help="result JSON path (a .csv goes beside; each finished episode is "
                        "appended to NAME.episodes.jsonl as it ends)")
    parser.add_argument("--resume", action="store_true",
                        help="keep the episodes already in NAME.episodes.jsonl and run the rest")
    add_backend_arguments(parser)
    args = parser.parse_args(argv)
    check_backend_arguments(parser, args)
    try:                                # every output checked, then locked, before work
        if args.protocol:
            _settings_folder(args.out)
        else:
            checked_output_file(stream_path(args.out), "--out's episode stream")
        with OutputLock(args.out):
            return _protocol_cell(args) if args.protocol else _seeded_episodes(args)
    except ValueError as err:
        parser.exit(2, f"homing-eval: error: {err}\n")
    except OSError as err:              # e.g. the disk filled while writing the result
        parser.exit(2, f"homing-eval: error: {err}\n")
    except (WorkerDiedError, KeyboardInterrupt) as err:   # Ctrl-C, SIGTERM, SIGHUP too
        kept = (f"the settings' streams in {os.path.splitext(args.out)[0]}/" if args.protocol
                else stream_path(args.out))
        end_stopped_command(parser, err, f"the finished episodes are in {kept}: the same "
                                         f"command with --resume runs the rest")


def _seeded_episodes(args) -> int:
    """Without ``--protocol``: evaluate the method on the seeded episodes, write the
    result and print its summary."""
    spec = policy_from_args(args)
    result = evaluate(spec, args.env, 100 if args.episodes is None else args.episodes,
                      args.seed or 0, env_kwargs_from_args(args), args.workers,
                      bin_width=args.bin_width, progress=not args.quiet,
                      stream=stream_path(args.out), resume=args.resume,
                      backend=args.backend, address=args.ray_address)
    result.save(args.out)
    if spec.kind == "sb3" and (recorded := recorded_settings(spec.source)).source:
        print(f"settings recorded in {recorded.source} (explicit --env-kwargs/--param "
              f"override them): env kwargs {result.env_kwargs}, params {result.params}")
    print(format_summary(result))
    print(f"wrote {args.out} and {os.path.splitext(args.out)[0]}.csv")
    return 0


if __name__ == "__main__":
    sys.exit(main())
