//! Scenes: the plan of every example scene, that skipped stages do no work (by the
//! work counters of debug builds), that unused attributes change nothing, and that
//! bad scene files are rejected with the key, file and line.

use std::path::{Path, PathBuf};

use termrast::counters::{self, Stage};
use termrast::raster::Target;
use termrast::scene::render::{SceneFrame, SceneView};
use termrast::scene::{Scene, SceneError};

fn examples() -> Vec<PathBuf> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let mut v: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("examples/scenes")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    assert!(v.len() >= 6, "example scenes: {v:?}");
    v
}

fn name(p: &Path) -> String {
    p.file_stem().unwrap().to_string_lossy().into_owned()
}

/// Each example scene's plan, as `termrast render SCENE --plan` prints it.
#[test]
fn example_scene_plans() {
    for path in examples() {
        let scene = Scene::load(&path).unwrap_or_else(|e| panic!("{e}"));
        insta::assert_snapshot!(format!("plan_{}", name(&path)), scene.plan.to_string());
    }
}

/// The stages of the plan and the counters that show their work.
const STAGES: [(&str, &[Stage]); 11] = [
    ("normals", &[Stage::NormalsTransformed]),
    ("world positions", &[Stage::PositionsToWorld]),
    ("vertex colours", &[Stage::VertexColors]),
    ("texture coordinates", &[Stage::Uvs]),
    ("lighting", &[Stage::Lighting]),
    ("texture lookups", &[Stage::TextureSamples]),
    ("fog", &[Stage::Fog]),
    ("depth shading", &[Stage::DepthShading]),
    ("depth test", &[Stage::DepthTests]),
    ("wireframe", &[Stage::WireEdges]),
    ("silhouettes", &[Stage::SilhouetteEdges]),
];

/// Pass: for every example scene, every stage the plan skips did no work in a frame,
/// and every stage it runs did some; the frame-wide buffers likewise (no depth clears
/// without a depth buffer, no resolves without supersampling); and the pipelines are
/// compiled for exactly the planned varyings.
#[test]
fn skipped_stages_do_no_work() {
    assert!(counters::enabled(), "the tests run with debug assertions");
    for path in examples() {
        counters::reset();
        let scene = Scene::load(&path).unwrap();
        let loaded = counters::snapshot();
        let mut frame = SceneFrame::new(&scene);
        let planned: Vec<_> = scene.plan.objects.iter().map(|o| o.varyings).collect();
        assert_eq!(frame.varyings(), planned, "{}", name(&path));
        // Objects are drawn one at a time below so each one's counts are its own.
        let view = SceneView {
            time: 0.7,
            pixel_aspect: 0.5,
            ..SceneView::default()
        };
        counters::reset();
        frame.draw(&scene, Target::new(120, 64), &view);
        let counts = counters::snapshot();
        let n = name(&path);
        // Frame-wide.
        assert_eq!(
            counts.get(Stage::DepthClears) > 0,
            scene.plan.depth_buffer,
            "{n}: depth clears"
        );
        assert_eq!(
            counts.get(Stage::Resolves) > 0,
            scene.plan.samples > 1,
            "{n}: resolves"
        );
        assert_eq!(
            frame.renderer.has_depth(),
            scene.plan.depth_buffer,
            "{n}: depth buffer exists"
        );
        // Normals are generated at load only when some object lights.
        let lit = scene.plan.objects.iter().any(|o| o.normals && !o.unweld);
        if !lit {
            assert_eq!(
                loaded.get(Stage::NormalsGenerated),
                0,
                "{n}: normals generated"
            );
        }
        // Per stage: on in some object ⇔ work done (objects do not share stages here
        // in a way that would mask one another: a stage on anywhere must show work,
        // a stage off everywhere must show none).
        for (stage, counters_of) in STAGES {
            let on_anywhere = scene
                .plan
                .objects
                .iter()
                .any(|o| o.lines.iter().any(|l| l.stage == stage && l.on));
            let work: u64 = counters_of.iter().map(|&c| counts.get(c)).sum();
            if on_anywhere {
                assert!(work > 0, "{n}: {stage} is on but did nothing");
            } else {
                assert_eq!(
                    work, 0,
                    "{n}: {stage} is skipped but did {work} units of work"
                );
            }
        }
    }
}

/// Pass: an attribute present in the model but used by no stage changes nothing: the
/// cube with texture coordinates renders bit for bit like the cube without them, and
/// the plan drops them at load.
#[test]
fn unused_attributes_do_not_change_the_output() {
    let dir = std::env::temp_dir().join(format!("termrast-scenes-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let with = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/cube.obj"),
    )
    .unwrap();
    // The same cube without `vt` lines, material or texture indices.
    let without: String = with
        .lines()
        .filter(|l| !l.starts_with("vt") && !l.starts_with("mtllib") && !l.starts_with("usemtl"))
        .map(|l| {
            if let Some(rest) = l.strip_prefix("f ") {
                let v: Vec<&str> = rest
                    .split_whitespace()
                    .map(|c| c.split('/').next().unwrap())
                    .collect();
                format!("f {}", v.join(" "))
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    std::fs::write(dir.join("with.obj"), &with).unwrap();
    std::fs::copy(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/cube.mtl"),
        dir.join("cube.mtl"),
    )
    .unwrap();
    std::fs::write(dir.join("without.obj"), &without).unwrap();
    let scene = |model: &str| {
        let text = format!(
            "[[object]]\nmodel = \"{model}\"\nrotation = [20, 30, 0]\nscale = 0.6\n[object.material]\nlighting = \"lambert\"\n[object.effects]\ndepth_test = true\nfog = {{ start = 2.0, end = 3.5 }}\n"
        );
        Scene::from_text(&text, &dir.join("scene.toml")).unwrap()
    };
    let (a, b) = (scene("with.obj"), scene("without.obj"));
    assert!(
        a.objects[0].mesh.uvs.is_empty(),
        "unused uvs are dropped at load"
    );
    let render = |s: &Scene| {
        let mut f = SceneFrame::new(s);
        f.draw(s, Target::new(80, 60), &SceneView::default());
        f.color.0.clone()
    };
    let (ra, rb) = (render(&a), render(&b));
    assert!(ra.iter().filter(|p| p[3] == 255).count() > 500);
    assert_eq!(ra, rb);
    std::fs::remove_dir_all(&dir).ok();
}

fn error_of(text: &str) -> String {
    match Scene::from_text(text, Path::new("bad.toml")) {
        Ok(_) => panic!("accepted: {text}"),
        Err(e) => e.to_string(),
    }
}

/// Pass: unknown keys, bad values and missing files are rejected with a message that
/// names the file (and line), the key or value, and what is allowed.
#[test]
fn bad_scenes_are_rejected_clearly() {
    let e = error_of("[[object]]\nmodel = \"teapot\"\n[object.material]\ncolour = [1, 0, 0]\n");
    assert!(
        e.starts_with("bad.toml:4:") && e.contains("`colour`") && e.contains("`color`"),
        "{e}"
    );
    let e = error_of("[[object]]\nmodel = \"teapot\"\n[object.material]\nlighting = \"phong\"\n");
    assert!(
        e.contains("bad.toml:4") && e.contains("phong") && e.contains("blinn-phong"),
        "{e}"
    );
    let e = error_of("[render]\nantialias = 3\n[[object]]\nmodel = \"teapot\"\n");
    assert!(e.contains("bad.toml:2") && e.contains("1, 4 and 16"), "{e}");
    let e = error_of(
        "[[light]]\nkind = \"point\"\ndirection = [0, 1, 0]\n[[object]]\nmodel = \"teapot\"\n",
    );
    assert!(
        e.contains("bad.toml:3") && e.contains("`direction` does not apply to a point light"),
        "{e}"
    );
    let e = error_of("[camera]\nnear = 5\nfar = 1\n[[object]]\nmodel = \"teapot\"\n");
    assert!(e.contains("near") && e.contains("far"), "{e}");
    let e = error_of("");
    assert!(e.contains("no objects"), "{e}");
    let e = error_of("[[object]]\nmodel = \"missing.obj\"\n");
    assert!(e.contains("object 1") && e.contains("missing.obj"), "{e}");
    let e = error_of("[[object]]\nmodel = \"teapot\"\n[object.material]\nvertex_colors = true\n");
    assert!(e.contains("no vertex colours"), "{e}");
    let e = error_of("[[object]]\nmodel = \"teapot\"\n[object.material]\ntexture = \"nearest\"\n");
    assert!(e.contains("no texture coordinates"), "{e}");
    let e = error_of(
        "[[object]]\nmodel = \"sphere:100\"\n[object.material]\ntexture = \"nearest\"\nimage = \"nope.png\"\n",
    );
    assert!(e.contains("nope.png"), "{e}");
    let e = error_of("[[object]]\nmodel = \"teapot\"\nscale = -1\n");
    assert!(e.contains("bad.toml:3") && e.contains("scale"), "{e}");
    assert!(matches!(
        Scene::load(Path::new("no/such/scene.toml")),
        Err(SceneError::Io { .. })
    ));
}

/// Pass: the minimal scene (every effect off) allocates no depth buffer and draws the
/// silhouette in the material colour; the default scene of a model has a depth test
/// and per-pixel lighting.
#[test]
fn minimal_and_default_scenes() {
    let minimal =
        Scene::from_text("[[object]]\nmodel = \"teapot\"\n", Path::new("m.toml")).unwrap();
    let mut f = SceneFrame::new(&minimal);
    f.draw(&minimal, Target::new(64, 48), &SceneView::default());
    assert!(!f.renderer.has_depth() && f.renderer.depth.capacity_bytes() == 0);
    let covered: Vec<_> = f.color.0.iter().filter(|p| p[3] == 255).collect();
    assert!(covered.len() > 200 && covered.iter().all(|p| p[..3] == [255, 255, 255]));
    let default = Scene::for_model("teapot").unwrap();
    let o = &default.plan.objects[0];
    assert!(o.depth_test && o.varyings.normal && default.plan.depth_buffer);
}

/// Pass: the binary prints a scene's plan, and refuses a bad scene with its message
/// and a non-zero exit, not a panic.
#[test]
fn render_plan_and_bad_scene_from_the_command_line() {
    let bin = env!("CARGO_BIN_EXE_termrast");
    let minimal = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/minimal.toml");
    let out = std::process::Command::new(bin)
        .args(["render", minimal.to_str().unwrap(), "--plan"])
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("depth buffer: skipped") && text.contains("normals: skipped (no lighting)"),
        "{text}"
    );
    let dir = std::env::temp_dir().join(format!("termrast-bad-scene-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("bad.toml");
    std::fs::write(
        &bad,
        "[[object]]\nmodel = \"teapot\"\n[object.effects]\nfog = { start = 5, end = 1 }\n",
    )
    .unwrap();
    let out = std::process::Command::new(bin)
        .args([
            "render",
            bad.to_str().unwrap(),
            "--cols",
            "20",
            "--rows",
            "6",
        ])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("bad.toml:4") && err.contains("fog") && !err.contains("panicked"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// Pass: an object whose plan is exactly the standard one (a model's default scene,
/// and the coloured lit teapot) is drawn by the lane-code Lambert pipeline, one with
/// vertex colours besides (the sphere's) by its coloured form, and a model's scene has
/// the bits the model's standard frame had seen the same way (as recorded in
/// `model_frames`); one of a single flat colour (the minimal scene) takes the
/// flat-colour pipeline, one whose only varying is a colour the interpolated-colour
/// pipeline; any other plan takes the packed shader.
#[test]
fn the_standard_plan_takes_the_lambert_pipeline() {
    let target = Target::new(160, 120);
    for (spec, pipeline) in [
        ("teapot", "lambert"),
        ("bunny", "lambert"),
        ("sphere:20000", "lambert-colors"),
    ] {
        let scene = Scene::for_model(spec).unwrap();
        let mut frame = SceneFrame::new(&scene);
        assert_eq!(frame.pipelines(), [pipeline], "{spec}");
        frame.draw(&scene, target, &SceneView::default());
        let color = &frame.color.0;
        assert!(color.iter().filter(|p| p[3] == 255).count() > 1000);
        let recorded = crate::model_frames::recorded_colour(
            spec,
            "framed a0 t0 z1 pa1 Fill Perspective wide 160x120",
        );
        let hash = crate::model_frames::hash(color.iter().flatten().copied());
        assert_eq!(hash, recorded, "{spec}: the frames differ");
    }
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    for (file, pipelines) in [("lit-teapot.toml", ["lambert"]), ("minimal.toml", ["flat"])] {
        let scene = Scene::load(&examples.join(file)).unwrap();
        assert_eq!(SceneFrame::new(&scene).pipelines(), pipelines, "{file}");
    }
    let fog = Scene::from_text(
        "[[object]]\nmodel = \"teapot\"\n[object.material]\nlighting = \"lambert\"\n\
         [object.effects]\ndepth_test = true\nfog = { start = 2.0, end = 3.5 }\n",
        Path::new("fog.toml"),
    )
    .unwrap();
    assert_eq!(SceneFrame::new(&fog).pipelines(), ["packed"]);
    // A colour interpolated from the vertices, and nothing else on the surface.
    for material in ["lighting = \"gouraud\"", "vertex_colors = true"] {
        let text = format!(
            "[[object]]\nmodel = \"sphere:500\"\n[object.material]\n{material}\n\
             [object.effects]\ndepth_test = true\n"
        );
        let scene = Scene::from_text(&text, Path::new("colour.toml")).unwrap();
        assert_eq!(
            SceneFrame::new(&scene).pipelines(),
            ["vertex-color"],
            "{text}"
        );
    }
    // The sphere without its colours, with them, and lit by lights of the file's own.
    for (material, lights, pipeline) in [
        ("", "", "lambert"),
        ("vertex_colors = true\n", "", "lambert-colors"),
        ("from_model = true\n", "", "lambert-colors"),
        (
            "from_model = true\n",
            "[[light]]\nkind = \"ambient\"\n",
            "packed",
        ),
    ] {
        let text = format!(
            "{lights}[[object]]\nmodel = \"sphere:500\"\n[object.material]\n\
             lighting = \"lambert\"\n{material}[object.effects]\ndepth_test = true\n"
        );
        let scene = Scene::from_text(&text, Path::new("sphere.toml")).unwrap();
        assert_eq!(SceneFrame::new(&scene).pipelines(), [pipeline], "{text}");
    }
}

/// Pass: a model's scene without its vertex colours (`bench render
/// --no-vertex-colors`) takes the plain Lambert pipeline, and draws the sphere's
/// pixels at the same depths as with them, in grey (a white material under white
/// lights) where with them they are coloured.
#[test]
fn a_model_without_its_vertex_colours_is_drawn_white() {
    let target = Target::new(160, 120);
    let coloured = Scene::standard("sphere:2000").unwrap();
    let mut white = coloured.clone();
    white.drop_vertex_colors();
    assert!(white.objects[0].mesh.colors.is_empty());
    let mut frames = [&coloured, &white].map(|scene| {
        let mut frame = SceneFrame::new(scene);
        frame.draw(scene, target, &SceneView::default());
        frame
    });
    assert_eq!(frames[0].pipelines(), ["lambert-colors"]);
    assert_eq!(frames[1].pipelines(), ["lambert"]);
    let [c, w] = &mut frames;
    assert_eq!(c.renderer.depth.to_vec(), w.renderer.depth.to_vec());
    let covered = |p: &[u8; 4]| p[3] == 255;
    let grey = |p: &[u8; 4]| p[0] == p[1] && p[1] == p[2];
    let pairs = || c.color.0.iter().zip(&w.color.0);
    assert!(pairs().all(|(a, b)| covered(a) == covered(b)));
    assert!(pairs().filter(|(a, _)| covered(a)).count() > 5000);
    assert!(pairs().all(|(_, b)| !covered(b) || grey(b)));
    assert!(pairs().filter(|(a, _)| covered(a) && !grey(a)).count() > 5000);
}

/// Pass: `fill = false` draws an object's edges and nothing of its triangles: the plan
/// says so, there is no depth buffer, every pixel drawn is a wire pixel, and no
/// fragment is depth-tested or lit. Filling it again (the viewer's `w`) gives the plan
/// and the bits of the scene loaded filled; edges a plan did not load are computed
/// when a wireframe is turned on, the same as loaded.
#[test]
fn fill_off_draws_only_edges() {
    use termrast::render::target::to_u8;
    use termrast::render::wire::{Mode, WIRE_COLOR};
    let text = |effects: &str| {
        format!(
            "[[object]]\nmodel = \"teapot\"\n[object.material]\nlighting = \"lambert\"\n\
             [object.effects]\ndepth_test = true\n{effects}"
        )
    };
    let load = |effects: &str| Scene::from_text(&text(effects), Path::new("w.toml")).unwrap();
    let mut scene = load("wireframe = true\nfill = false\n");
    let plan = scene.plan.to_string();
    assert!(
        plan.contains("triangles: skipped (fill = false")
            && plan.contains("depth test: skipped (fill = false")
            && plan.contains("lighting: skipped (fill = false")
            && plan.contains("wireframe: on (every edge")
            && !scene.plan.depth_buffer,
        "{plan}"
    );
    assert_eq!(scene.mode(), Some(Mode::Wire));
    let target = Target::new(96, 64);
    let mut frame = SceneFrame::new(&scene);
    counters::reset();
    frame.draw(&scene, target, &SceneView::default());
    let c = counters::snapshot();
    assert_eq!(
        [Stage::DepthTests, Stage::Lighting, Stage::DepthClears].map(|s| c.get(s)),
        [0; 3]
    );
    assert!(c.get(Stage::WireEdges) > 0 && !frame.renderer.has_depth());
    let wire = WIRE_COLOR.to_array().map(to_u8);
    let drawn: Vec<_> = frame.color.0.iter().filter(|p| p[3] == 255).collect();
    assert!(drawn.len() > 300 && drawn.iter().all(|p| p[..3] == wire));
    assert!(frame.probe(&scene, 48, 32)[0].records.is_empty());

    scene.set_mode(Mode::FillWire);
    let filled = load("wireframe = true\n");
    assert_eq!(scene.plan, filled.plan);
    frame.draw(&scene, target, &SceneView::default());
    let mut reference = SceneFrame::new(&filled);
    reference.draw(&filled, target, &SceneView::default());
    assert!(frame.renderer.has_depth());
    assert!(frame.color.0 == reference.color.0, "the frames differ");

    let mut plain = load("");
    assert!(
        plain.objects[0].edges.is_empty(),
        "no edges without a wireframe"
    );
    plain.set_mode(Mode::Wire);
    assert_eq!(plain.objects[0].edges, filled.objects[0].edges);
}
