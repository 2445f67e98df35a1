//! The layers import downward only: no module of any crate of the workspace imports, through
//! any chain of imports, a module that imports it back.
//!
//! A module's imports are the `crate::`, `super::` and `self::` paths in its file (its `use`
//! items and the paths in its code, tests left out), each resolved to the module that defines
//! the item: the longest module the path names, followed through that module's `pub use`
//! re-exports. Edges to the crate root (which declares every module) are left out. The loops
//! are the strongly connected sets of two or more modules of that graph (petgraph's Tarjan).
#![allow(clippy::unwrap_used, clippy::expect_used)] // a test: a broken fixture stops it where it breaks

use petgraph::algo::tarjan_scc;
use petgraph::graph::DiGraph;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use syn::visit::Visit;

type Module = Vec<String>;

/// Every module of the crate whose sources are in `src`, by its file.
fn modules(src: &Path) -> BTreeMap<Module, PathBuf> {
    let mut out = BTreeMap::new();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                if path.file_name().is_some_and(|n| n != "bin") {
                    stack.push(path);
                }
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let rel = path.strip_prefix(src).unwrap().with_extension("");
            let mut m: Module = rel
                .iter()
                .map(|c| c.to_string_lossy().into_owned())
                .collect();
            if matches!(m.last().map(String::as_str), Some("lib" | "main" | "mod")) {
                m.pop();
            }
            out.insert(m, path);
        }
    }
    out
}

/// The paths a file names (with the module they are relative to) and its `pub use` items.
#[derive(Default)]
struct Names {
    paths: Vec<Vec<String>>,
    reexports: Vec<(String, Vec<String>)>,
}

impl Names {
    fn use_tree(&mut self, tree: &syn::UseTree, prefix: &mut Vec<String>, public: bool) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(&p.tree, prefix, public);
                prefix.pop();
            }
            syn::UseTree::Name(n) => self.used(prefix, &n.ident.to_string(), None, public),
            syn::UseTree::Rename(r) => {
                let alias = r.rename.to_string();
                self.used(prefix, &r.ident.to_string(), Some(alias), public);
            }
            syn::UseTree::Glob(_) => self.paths.push(prefix.clone()),
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(t, prefix, public);
                }
            }
        }
    }

    fn used(&mut self, prefix: &[String], name: &str, alias: Option<String>, public: bool) {
        let mut path = prefix.to_vec();
        if name != "self" {
            path.push(name.to_string());
        }
        if public {
            let shown = alias.unwrap_or_else(|| path.last().cloned().unwrap_or_default());
            self.reexports.push((shown, path.clone()));
        }
        self.paths.push(path);
    }
}

fn is_test(attrs: &[syn::Attribute]) -> bool {
    attrs.iter().any(|a| {
        a.path().is_ident("cfg")
            && a.parse_args::<syn::Meta>()
                .is_ok_and(|m| m.path().is_ident("test"))
    })
}

impl<'ast> Visit<'ast> for Names {
    fn visit_item_mod(&mut self, m: &'ast syn::ItemMod) {
        if !is_test(&m.attrs) {
            syn::visit::visit_item_mod(self, m);
        }
    }

    fn visit_item_fn(&mut self, f: &'ast syn::ItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_item_fn(self, f);
        }
    }

    fn visit_impl_item_fn(&mut self, f: &'ast syn::ImplItemFn) {
        if !is_test(&f.attrs) {
            syn::visit::visit_impl_item_fn(self, f);
        }
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        if !is_test(&u.attrs) {
            let public = matches!(u.vis, syn::Visibility::Public(_));
            self.use_tree(&u.tree, &mut Vec::new(), public);
        }
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        self.paths
            .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        syn::visit::visit_path(self, p);
    }
}

/// The module `path` (written in module `from`) starts from, and the rest of the path.
fn anchor(from: &Module, path: &[String]) -> Option<(Module, Vec<String>)> {
    let (first, rest) = path.split_first()?;
    match first.as_str() {
        "crate" => Some((Vec::new(), rest.to_vec())),
        "self" => Some((from.clone(), rest.to_vec())),
        "super" => {
            let mut base = from.clone();
            base.pop();
            let mut rest = rest.to_vec();
            while rest.first().is_some_and(|s| s == "super") {
                base.pop();
                rest.remove(0);
            }
            Some((base, rest))
        }
        _ => None,
    }
}

struct Crate {
    files: BTreeMap<Module, PathBuf>,
    names: BTreeMap<Module, Names>,
}

impl Crate {
    fn read(src: &Path) -> Self {
        let files = modules(src);
        let names = files
            .iter()
            .map(|(m, f)| {
                let text = std::fs::read_to_string(f).unwrap();
                let file = syn::parse_file(&text).unwrap_or_else(|e| panic!("{f:?}: {e}"));
                let mut n = Names::default();
                n.visit_file(&file);
                (m.clone(), n)
            })
            .collect();
        Self { files, names }
    }

    /// The module that defines what `path` (relative to `base`) names.
    fn resolve(&self, base: Module, path: &[String], depth: usize) -> Option<Module> {
        let mut module = base;
        let mut k = 0;
        while k < path.len() {
            let mut next = module.clone();
            next.push(path[k].clone());
            if !self.files.contains_key(&next) {
                break;
            }
            module = next;
            k += 1;
        }
        if !self.files.contains_key(&module) {
            return None;
        }
        // An item the module re-exports is defined where the re-export points.
        if let (Some(name), true) = (path.get(k), depth < 8) {
            let names = &self.names[&module];
            if let Some((_, target)) = names.reexports.iter().find(|(n, _)| n == name) {
                let (b, rest) =
                    anchor(&module, target).unwrap_or_else(|| (module.clone(), target.clone()));
                if let Some(m) = self.resolve(b, &rest, depth + 1) {
                    return Some(m);
                }
            }
        }
        Some(module)
    }

    fn graph(&self) -> BTreeMap<Module, BTreeSet<Module>> {
        let mut edges = BTreeMap::new();
        for (m, names) in &self.names {
            let mut out = BTreeSet::new();
            let mut paths = names.paths.clone();
            // A re-export of a child (`pub use child::Item`) is an import of it.
            paths.extend(names.reexports.iter().map(|(_, p)| {
                let mut full = vec!["self".to_string()];
                full.extend(p.iter().cloned());
                full
            }));
            for p in &paths {
                let Some((base, rest)) = anchor(m, p) else {
                    continue;
                };
                if let Some(t) = self.resolve(base, &rest, 0)
                    && &t != m
                    && !t.is_empty()
                {
                    out.insert(t);
                }
            }
            edges.insert(m.clone(), out);
        }
        edges
    }
}

/// The import loops of the crate whose sources are in `src`, each as its modules' names.
fn loops(src: &Path) -> Vec<Vec<String>> {
    let edges = Crate::read(src).graph();
    let mut g = DiGraph::<&Module, ()>::new();
    let ids: BTreeMap<&Module, _> = edges.keys().map(|m| (m, g.add_node(m))).collect();
    for (m, targets) in &edges {
        for t in targets {
            if let Some(&to) = ids.get(t) {
                g.add_edge(ids[m], to, ());
            }
        }
    }
    tarjan_scc(&g)
        .into_iter()
        .filter(|c| c.len() > 1)
        .map(|c| {
            let mut names: Vec<String> = c.iter().map(|&i| g[i].join("::")).collect();
            names.sort();
            names
        })
        .collect()
}

fn workspace_crates() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    [
        "src",
        "problem/src",
        "sim/src",
        "vision/src",
        "control/src",
        "robot/src",
        "python/src",
    ]
    .iter()
    .map(|d| root.join(d))
    .collect()
}

#[test]
fn no_crate_of_the_workspace_has_a_module_import_loop() {
    let mut found = Vec::new();
    for src in workspace_crates() {
        for l in loops(&src) {
            found.push(format!("{}: {}", src.display(), l.join(", ")));
        }
    }
    assert!(
        found.is_empty(),
        "module import loops:\n{}",
        found.join("\n")
    );
}

#[test]
fn the_check_finds_a_loop_when_there_is_one() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("layers_loop");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("b")).unwrap();
    let write = |f: &str, text: &str| std::fs::write(dir.join(f), text).unwrap();
    write("lib.rs", "pub mod a;\npub mod b;\npub mod c;\n");
    write("a.rs", "use crate::b::Thing;\npub struct A;\n");
    write("b/mod.rs", "mod inner;\npub use inner::Thing;\n");
    write("b/inner.rs", "pub struct Thing(crate::c::C);\n");
    write("c.rs", "pub struct C(super::a::A);\n");
    let found = loops(&dir);
    assert_eq!(found, vec![vec!["a", "b::inner", "c"]], "{found:?}");
    // Without the way back there is none.
    write("c.rs", "pub struct C;\n");
    assert!(loops(&dir).is_empty());
    // A test-only method's paths are not imports of the module (as test functions are not).
    write(
        "c.rs",
        "pub struct C;\nimpl C {\n    #[cfg(test)]\n    pub(super) fn a() -> super::a::A {\n        super::a::A\n    }\n}\n",
    );
    assert!(loops(&dir).is_empty());
}
