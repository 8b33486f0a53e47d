#!/usr/bin/env python3
"""Every #include "rdm/<part>/..." in libs/<part>/ names the part itself or one it links
(directly or through lower parts), as declared in libs/CMakeLists.txt and written by CMake to
rdm_parts.txt. Also checks that each part's headers live in include/rdm/<part>/ and that no
part's file includes a program (server/, cli/, viewer/).

usage: layers_test.py SOURCE_DIR PARTS_FILE
"""
import os
import re
import sys

INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


def read_parts(path):
    layers, deps = {}, {}
    with open(path) as f:
        for line in f:
            fields = line.split()
            if fields:
                layers[fields[0]] = int(fields[1])
                deps[fields[0]] = fields[2:]
    return layers, deps


def closure(part, deps):
    seen, frontier = {part}, [part]
    while frontier:
        for d in deps[frontier.pop()]:
            if d not in seen:
                seen.add(d)
                frontier.append(d)
    return seen


def main():
    source_dir, parts_file = sys.argv[1], sys.argv[2]
    layers, deps = read_parts(parts_file)
    errors = []
    libs = os.path.join(source_dir, 'libs')
    for part in sorted(layers):
        allowed = closure(part, deps)
        for root, _, files in os.walk(os.path.join(libs, part)):
            for name in files:
                path = os.path.join(root, name)
                rel = os.path.relpath(path, source_dir)
                if not name.endswith(('.h', '.cpp')):
                    continue
                if '/include/' in rel and not rel.startswith(f'libs/{part}/include/rdm/{part}/'):
                    errors.append(f'{rel}: a header of part {part} belongs in include/rdm/{part}/')
                for target in INCLUDE.findall(open(path).read()):
                    m = re.match(r'rdm/([a-z]+)/', target)
                    if m and m.group(1) in layers and m.group(1) not in allowed:
                        errors.append(f'{rel}: includes "{target}", but part {part} (layer '
                                      f'{layers[part]}) may use only {sorted(allowed)}')
                    elif target.split('/')[0] in ('server', 'cli', 'viewer', 'app', 'renderer'):
                        errors.append(f'{rel}: includes the program header "{target}"')
    for e in errors:
        print(e)
    print(f'{len(layers)} parts checked, {len(errors)} upward include(s)')
    return 1 if errors else 0


if __name__ == '__main__':
    sys.exit(main())
