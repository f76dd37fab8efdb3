#!/usr/bin/env python3
"""Feeds sonarbench damaged copies of a good input and checks that it never crashes.

    python3 tools/mutate_inputs.py build/sim/sonarbench scene scenes/cras-tank.yaml --cases 400
    python3 tools/mutate_inputs.py build/sim/sonarbench mat data/cras-tank-static/dataset_static.mat
    python3 tools/mutate_inputs.py build/sim/sonarbench mesh scenes/meshes/quay_wall.ply --seed 9
    python3 tools/mutate_inputs.py build/sim/sonarbench bag fuzz/corpus/rosbag/flat.mcap

scene: each `key: value` line's value replaced by one of a set of bad values (a negative, zero,
    huge, NaN, a string, "", a list, a mapping, null), the copy simulated (`simulate --shard
    1/1000`: the scene is read whole, one sweep is made);
mat, bag: the file cut at fixed offsets, then copies with 1-8 bytes changed, each imported (a
    .mat log, or a ROS 2 bag);
mesh: copies cut, with bytes or digits changed or a run of bytes repeated, each loaded as the one
    mesh of a small scene and simulated.

A case passes when sonarbench exits 0, or 2 with its message on stderr and nothing left in --out,
within 30 s and without a sanitizer's report. Prints each failure (the input kept under --keep)
and a summary; exits 1 if any case failed. Same seed, same cases.
"""
import argparse
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile

BAD_VALUES = ['-1', '0', '1e308', '.nan', '.inf', 'abc', '""', '[1, 2]', '1e-300', '{a: 1}', '~',
              '-0.0', '2147483648', '-9999999999']
KEY_VALUE = re.compile(r'^(\s*-?\s*)([A-Za-z_]+):\s*(\S.*?)\s*(#.*)?$')
PATH_KEY = re.compile(r'^(\s*-?\s*(?:sensor_model|extends|file):\s*)(\S+)(.*)$')


def absolute_paths(text, directory):
    """The scene's relative paths made absolute, so that a copy elsewhere means the same files."""
    def fix(match):
        path = match.group(2).strip('"\'')
        if not os.path.isabs(path):
            path = os.path.normpath(os.path.join(directory, path))
        return match.group(1) + path + match.group(3)
    return '\n'.join(PATH_KEY.sub(fix, line) for line in text.split('\n'))


def scene_cases(path, rng):
    lines = absolute_paths(open(path).read(), os.path.dirname(os.path.abspath(path))).split('\n')
    cases = []
    for i, line in enumerate(lines):
        match = KEY_VALUE.match(line)
        if not match or (match.group(3).startswith('[') and not match.group(3).endswith(']')):
            continue
        for value in BAD_VALUES:
            changed = list(lines)
            changed[i] = match.group(1) + match.group(2) + ': ' + value
            cases.append(('line %d: %s' % (i + 1, changed[i].strip()), '\n'.join(changed)))
    rng.shuffle(cases)
    return cases


def byte_cases(data, rng, count, kinds):
    cases = []
    for k in range(count):
        d = bytearray(data)
        kind = rng.choice(kinds)
        if kind == 'flip':
            for _ in range(rng.choice([1, 1, 2, 8])):
                d[rng.choice([rng.randrange(min(300, len(d))), rng.randrange(len(d))])] = \
                    rng.randrange(256)
        elif kind == 'cut':
            d = d[:rng.randrange(len(d))]
        elif kind == 'digit':
            digits = [i for i, c in enumerate(d) if chr(c).isdigit()]
            for _ in range(3 if digits else 0):
                d[rng.choice(digits)] = ord(rng.choice('0123456789-.e'))
        else:  # repeat
            a, b = rng.randrange(len(d)), rng.randrange(len(d))
            d[a:a] = d[b:b + 50]
        cases.append(('%s %d' % (kind, k), bytes(d)))
    return cases


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('sonarbench')
    parser.add_argument('kind', choices=['scene', 'mat', 'bag', 'mesh'])
    parser.add_argument('input')
    parser.add_argument('--cases', type=int, default=100)
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--keep', default=None, help='where failing inputs are kept')
    args = parser.parse_args()
    rng = random.Random(args.seed)
    work = tempfile.mkdtemp(prefix='mutate_inputs-')
    out = os.path.join(work, 'out')
    ext = os.path.splitext(args.input)[1]
    target = os.path.join(work, 'input' + ext)
    if args.kind == 'scene':
        cases = scene_cases(args.input, rng)[:args.cases]
        command = ['simulate', target, '--out', out, '--shard', '1/1000', '--no-progress']
    elif args.kind in ('mat', 'bag'):
        data = open(args.input, 'rb').read()
        cuts = [0, 1, 4, 127, 128, 129, 135, 136, 200, 1000, len(data) // 4, len(data) // 2,
                len(data) - 1]
        cuts = [c for c in cuts if c < len(data)]
        cases = [('cut %d' % c, data[:c]) for c in cuts]
        cases += byte_cases(data, rng, max(args.cases - len(cases), 0), ['flip'])
        command = ['import', target, '--out', out]
    else:
        scene = os.path.join(work, 'scene.yaml')
        model = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'sensor-models',
                             'shad-micron.yaml')
        with open(scene, 'w') as f:
            f.write('name: mesh\nsensor_model: %s\nsweeps: 1\n'
                    'materials: [{name: m, reflectivity: 0.5}]\n'
                    'meshes: [{name: mesh, type: file, file: %s, material: m}]\n'
                    'trajectory: {type: static, position_m: [0, 0, 1]}\n'
                    % (os.path.normpath(model), target))
        cases = byte_cases(open(args.input, 'rb').read(), rng, args.cases,
                           ['flip', 'cut', 'digit', 'repeat'])
        command = ['simulate', scene, '--out', out, '--shard', '1/1000', '--no-progress']
    outcomes = {}
    failed = 0
    for name, content in cases:
        with open(target, 'wb' if isinstance(content, bytes) else 'w') as f:
            f.write(content)
        shutil.rmtree(out, ignore_errors=True)
        try:
            run = subprocess.run([args.sonarbench] + command, capture_output=True, timeout=30)
            code = run.returncode
            err = run.stderr.decode('utf-8', 'replace')
        except subprocess.TimeoutExpired:
            code, err = 'timeout', ''
        outcomes[code] = outcomes.get(code, 0) + 1
        why = None
        if code not in (0, 2):
            why = 'exit %s' % code
        elif 'Sanitizer' in err or 'runtime error' in err:
            why = 'sanitizer report'
        elif code == 2 and (not err.strip() or os.path.exists(out)):
            why = 'exit 2 without a message or with --out written'
        if why:
            failed += 1
            print('FAIL %s (%s): %s' % (name, why, err.strip()[-300:]))
            if args.keep:
                os.makedirs(args.keep, exist_ok=True)
                keep = os.path.join(args.keep, '%d%s' % (failed, ext))
                with open(keep, 'wb' if isinstance(content, bytes) else 'w') as f:
                    f.write(content)
    shutil.rmtree(work, ignore_errors=True)
    print('%s %s, seed %d: %d cases, %d failed; exits %s' % (
        args.kind, args.input, args.seed, len(cases), failed,
        ', '.join('%s: %d' % (k, v) for k, v in sorted(outcomes.items(), key=str))))
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
