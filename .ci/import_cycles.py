#!/usr/bin/env python3
"""Import circles between the files of each crate: exit 1 and name them if there are any.

A file imports another when it names an item defined there: a `use` path or an inline path
starting with `crate::`, `super::`, `self::` or a child module's name, resolved to the file that
defines the item (following `pub use` re-exports to the defining file). Comments and the inline
`#[cfg(test)] mod tests` at a file's end are not read. A module file (lib.rs, mod.rs) that defines
items its children use while using its children is a circle too, so such files stay facades.

Usage: python3 .ci/import_cycles.py [ROOT] [-v]   (-v: print the edges of each circle and why)
"""
import os, re, sys, glob
args = [a for a in sys.argv[1:] if a != '-v']
root = args[0] if args else '.'
verbose = '-v' in sys.argv
def modpath(src, f):
    rel = os.path.relpath(f, src)[:-3].split(os.sep)
    if rel[-1] in ('lib', 'main', 'mod'): rel = rel[:-1]
    return tuple(rel)
def strip(text):
    text = re.sub(r'//[^\n]*', '', text)
    m = re.search(r'#\[cfg\(test\)\]\s*mod tests\s*\{', text)
    if m: text = text[:m.start()]
    return text
def expand(s):
    # expand a use tree string like a::{b, c::{d}} into paths
    s = s.replace(' ', '').replace('\n', '')
    out = []
    def rec(prefix, t):
        # split top-level commas
        depth = 0; cur = ''; parts = []
        for ch in t:
            if ch == '{': depth += 1
            if ch == '}': depth -= 1
            if ch == ',' and depth == 0: parts.append(cur); cur = ''
            else: cur += ch
        if cur: parts.append(cur)
        for p in parts:
            if '{' in p:
                i = p.index('{'); pre = p[:i].rstrip(':'); inner = p[i+1:p.rindex('}')] if '}' in p else p[i+1:]
                rec(prefix + [x for x in pre.split('::') if x], inner)
            else:
                p = p.split(' as ')[0].split('as')[0] if False else re.split(r'\bas\b', p)[0]
                out.append(prefix + [x for x in p.split('::') if x])
    rec([], s)
    return out
total = 0
for cargo in sorted(glob.glob(os.path.join(root, 'crates/*/Cargo.toml')) + glob.glob(os.path.join(root, 'crates/*/*/Cargo.toml'))):
    src = os.path.join(os.path.dirname(cargo), 'src')
    files = sorted(glob.glob(src + '/**/*.rs', recursive=True))
    mods = {}
    for f in files:
        mods.setdefault(modpath(src, f), f)
    texts = {f: strip(open(f).read()) for f in files}
    # re-exports in every module file: name -> path
    reexp = {}
    for f in files:
        mp = modpath(src, f)
        for m in re.finditer(r'pub(?:\([^)]*\))?\s+use\s+([^;]+);', texts[f]):
            for p in expand(m.group(1)):
                if p and p[0] in ('crate',): p = p[1:]
                elif p and p[0] == 'self': p = list(mp) + p[1:]
                elif p and p[0] == 'super': p = list(mp[:-1]) + p[1:]
                else: p = list(mp) + p
                if p: reexp[tuple(mp) + (p[-1],)] = tuple(p)
    def resolve(path, depth=0):
        # longest module prefix
        path = tuple(path)
        best = ()
        for i in range(len(path), -1, -1):
            if path[:i] in mods: best = path[:i]; break
        if len(path) > len(best) and best + (path[len(best)],) in reexp and depth < 5:
            tgt = reexp[best + (path[len(best)],)]
            if tgt[:len(best)+1] != best + (path[len(best)],):
                return resolve(tgt + path[len(best)+1:], depth + 1)
        return mods.get(best)
    edges = {f: set() for f in files}
    why = {}
    for f in files:
        mp = modpath(src, f); t = texts[f]
        paths = []
        for m in re.finditer(r'\buse\s+([^;]+);', t):
            paths += expand(m.group(1))
        for m in re.finditer(r'\b((?:crate|super|self)(?:::\w+)+)', t):
            paths.append(m.group(1).split('::'))
        # child modules used bare
        children = {k[-1] for k in mods if k[:-1] == mp and len(k) == len(mp) + 1}
        for m in re.finditer(r'(?<![:\w])(\w+)((?:::\w+)+)', t):
            if m.group(1) in children: paths.append([m.group(1)] + m.group(2).split('::')[1:])
        for p in paths:
            if not p: continue
            if p[0] == 'crate': ap = p[1:]
            elif p[0] == 'self': ap = list(mp) + p[1:]
            elif p[0] == 'super':
                base = list(mp); q = p
                while q and q[0] == 'super': base = base[:-1]; q = q[1:]
                ap = base + q
            elif p[0] in children: ap = list(mp) + p
            else: continue
            g = resolve(ap)
            if g and g != f:
                edges[f].add(g); why.setdefault((f, g), '::'.join(p))
    # Tarjan
    index = {}; low = {}; st = []; on = set(); sccs = []; c = [0]
    sys.setrecursionlimit(10000)
    def sc(v):
        index[v] = low[v] = c[0]; c[0] += 1; st.append(v); on.add(v)
        for w in edges[v]:
            if w not in index: sc(w); low[v] = min(low[v], low[w])
            elif w in on: low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = st.pop(); on.discard(w); comp.append(w)
                if w == v: break
            if len(comp) > 1: sccs.append(comp)
    for v in files:
        if v not in index: sc(v)
    for comp in sccs:
        total += 1
        print('CYCLE:', ' '.join(os.path.relpath(x, root) for x in sorted(comp)))
        if verbose:
            for a in comp:
                for b in comp:
                    if b in edges[a]: print('   ', os.path.relpath(a, src), '->', os.path.relpath(b, src), '(', why[(a, b)], ')')
print('cycles:', total)
sys.exit(1 if total else 0)
