#!/usr/bin/env python3
"""Regenerates the modal tables of config/milling/*.yaml from the CSV tables beside this script
(copied from the published tables, docs/physics.md §6). Prints YAML to paste; run:
    python3 config/milling/data/generate_presets.py robot_sle | tian2024
"""
import csv, sys, os

here = os.path.dirname(os.path.abspath(__file__))

def rows(name):
    with open(os.path.join(here, name)) as f:
        return list(csv.DictReader(l for l in f if not l.startswith('#')))

def mode(fn, z, k):
    return "{natural_freq_hz: %s, damping_ratio: %s, stiffness_n_per_m: %s}" % (fn, z, k)

if sys.argv[1] == 'robot_sle':
    data = rows('robot_sle_modal.csv')
    def part(system, name, indent):
        out = [indent + "- name: " + name]
        for d in ('x', 'y'):
            out.append(indent + "  %s%s:" % (d, d))
            for r in data:
                if r['system'] == system and r['direction'] == d:
                    out.append(indent + "    - " + mode(r['fn_hz'], r['zeta'], r['k_n_per_m']))
        return "\n".join(out)
    print("  - name: robot_workpiece\n    parts:")
    print(part('robot', 'robot', '      '))
    print(part('workpiece', 'workpiece', '      '))
    print("  - name: machine_tool\n    parts:")
    print(part('machine_tool', 'machine_tool', '      '))
else:
    data = rows('tian2024_modal_positions.csv')
    for p in range(1, 6):
        print("  - name: position_%d\n    parts:\n      - name: tool_tip" % p)
        for d in ('xx', 'xy', 'yx', 'yy'):
            for r in data:
                if r['position'] == str(p) and r['direction'] == d:
                    z = float(r['zeta_pct']) / 100.0
                    print("        %s: [%s]" % (d, mode(r['fn_hz'], "%.5f" % z, r['k_n_per_m'])))
