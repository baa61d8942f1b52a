//! Scene input errors (one clear error each, naming file, key and value),
//! the effects list (what is not listed is not built), and the
//! `plyscape simulate` command end to end.
use crate::common::errors::{error_of, InputError};
use plyscape::scene::load_scene;
use plyscape::simulate::simulate;
use plyscape::study::Study;

/// A small valid scene: a pendulum rod on a revolute joint.
const BASE: &str = r#"
[study]
name = "pendulum"
[scene]
effects = ["gravity"]
[[scene.bodies]]
name = "rod"
mass = 1.0
com = [0.5, 0.0, 0.0]
inertia = [[1e-4, 0.0, 0.0], [0.0, 0.0834, 0.0], [0.0, 0.0, 0.0834]]
[[scene.joints]]
name = "pin"
type = "revolute"
body_i = "ground"
body_j = "rod"
point = [0.0, 0.0, 0.0]
axis = [0.0, 1.0, 0.0]
[scene.integrator]
rtol = 1e-6
t_end = 0.5
dt_out = 0.1
[scene.outputs]
quantities = ["pin.angle"]
"#;

#[test]
fn base_scene_runs() {
    let study = Study::parse("ok.toml", BASE).unwrap();
    let scene = load_scene(&study).unwrap();
    let (_, sim) = simulate(&scene).unwrap();
    assert_eq!(sim.rows.len(), 6);
}

#[test]
fn each_bad_input_names_file_key_and_value() {
    let cases: Vec<(String, &str, &str)> = vec![
        (BASE.replace("body_j = \"rod\"", "body_j = \"rood\""), "scene.joints[0].body_j", "rood"),
        (BASE.replace("axis = [0.0, 1.0, 0.0]", "axis = [0.0, 0.0, 0.0]"), "scene.joints[0].axis", "0"),
        (BASE.replace("mass = 1.0", "mass = -1.0"), "scene.bodies[0].mass", "-1"),
        (BASE.replace("[0.0, 0.0, 0.0834]]", "[0.0, 0.0, -0.0834]]"), "scene.bodies[0].inertia", "-0.0834"),
        (BASE.replace("rtol = 1e-6", "rtol = 2.0"), "scene.integrator.rtol", "2"),
        (BASE.replace("t_end = 0.5", "t_end = -0.5"), "scene.integrator.t_end", "-0.5"),
        (BASE.replace("effects = [\"gravity\"]", "effects = [\"gravitee\"]"), "scene.effects[0]", "gravitee"),
        (BASE.replace("\"pin.angle\"", "\"pn.angle\""), "scene.outputs.quantities[0]", "pn.angle"),
        (BASE.replace("type = \"revolute\"", "type = \"hinge\""), "scene.joints[0].type", "hinge"),
        (
            BASE.replace("quantities = [\"pin.angle\"]", "quantities = [\"pin.angle\"]\nplot = \"pin.angle\"\nplot_file = \"../x\""),
            "scene.outputs.plot_file",
            "../x",
        ),
        (
            BASE.to_string()
                + "[[scene.markers]]\nname = \"m\"\nbody = \"rod\"\npoint = [1.0, 0.0, 0.0]\n"
                + "[[scene.forces]]\ntype = \"spring\"\nmarker_i = \"m\"\nmarker_j = \"nowhere\"\nstiffness = 1.0\n",
            "scene.forces[0].marker_j",
            "nowhere",
        ),
        (
            BASE.replace("effects = [\"gravity\"]", "effects = [\"loads\"]")
                + "[[scene.forces]]\ntype = \"load\"\nbody = \"rod\"\n"
                + "table = [[0.0, 0, 0, 0, 0, 0, 0], [0.0, 1, 0, 0, 0, 0, 0]]\n",
            "scene.forces[0].table[1]",
            "[0.0, 1.0",
        ),
        (
            // A fixed joint and a joint driven to another angle about the
            // same axis: contradictory, cannot be projected.
            BASE.to_string()
                + "[[scene.joints]]\nname = \"lock\"\ntype = \"driven\"\nbody_i = \"ground\"\nbody_j = \"rod\"\n"
                + "point = [0.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\ndrive = [0.5]\n"
                + "[[scene.joints]]\nname = \"weld\"\ntype = \"fixed\"\nbody_i = \"ground\"\nbody_j = \"rod\"\n"
                + "point = [1.0, 0.0, 0.0]\naxis = [0.0, 1.0, 0.0]\n",
            "scene.joints",
            "max |Φ|",
        ),
    ];
    for (text, key, value) in cases {
        println!("case {key}");
        let InputError {
            file,
            key: k,
            value: v,
            ..
        } = error_of("bad.toml", &text, |study| {
            load_scene(study).and_then(|s| simulate(&s).map(|_| ()).map_err(study.locate("scene")))
        });
        assert_eq!(file, "bad.toml");
        assert_eq!(k, key, "value {v}");
        assert!(
            v.contains(value),
            "key {k}: value {v} should contain {value}"
        );
    }
}

#[test]
fn force_and_response_errors_name_key_value_and_the_expected_values() {
    let spring = |body: &str| {
        BASE.to_string()
            + "[[scene.forces]]\ntype = \"spring\"\nname = \"s\"\nstiffness = 1.0\n"
            + body
    };
    let load = |body: &str| BASE.to_string() + "[[scene.forces]]\ntype = \"load\"\n" + body;
    let actuator = |segments: &str| {
        BASE.replace(
            "effects = [\"gravity\"]",
            "effects = [\"gravity\", \"actuators\"]",
        ) + "[[scene.forces]]\ntype = \"actuator\"\njoint = \"pin\"\nsegments = ["
            + segments
            + "]\n"
    };
    let cases: Vec<(String, &str, &str, &[&str])> = vec![
        // A spring along an unknown joint, and a rest length on a torsion
        // spring (about a revolute joint).
        (
            spring("joint = \"slid\"\n"),
            "scene.forces[0].joint",
            "slid",
            &["prismatic, cylindrical or revolute joint", "(pin)"],
        ),
        (
            spring("joint = \"pin\"\nlength = 0.2\n"),
            "scene.forces[0].length",
            "0.2",
            &["no length or force on a torsion spring"],
        ),
        (
            spring("joint = \"pin\"\nmarker_i = \"pin.i\"\nmarker_j = \"pin.j\"\n"),
            "scene.forces[0].joint",
            "pin",
            &["not both"],
        ),
        // A load at an unknown marker lists the markers there are.
        (
            load("marker = \"nowhere\"\nforce = [1.0, 0.0, 0.0]\n"),
            "scene.forces[0].marker",
            "nowhere",
            &["pin.i, pin.j"],
        ),
        (
            load("marker = \"pin.j\"\nframe = \"bodyy\"\n"),
            "scene.forces[0].frame",
            "bodyy",
            &["`global`", "`body`"],
        ),
        (
            load("force = [1.0, 0.0, 0.0]\n"),
            "scene.forces[0].body",
            "(missing)",
            &["or marker"],
        ),
        (
            BASE.replace("quantities = [\"pin.angle\"]", "quantities = [\"pin.displacement\"]"),
            "scene.outputs.quantities[0]",
            "pin.displacement",
            &["prismatic or cylindrical"],
        ),
        (
            BASE.to_string() + "[[scene.responses]]\nname = \"G\"\nkind = \"integral\"\nof = [\"rod.kinetic\"]\n",
            "scene.responses[0].of[0]",
            "rod.kinetic",
            &["<body>.kinetic_energy"],
        ),
        (
            BASE.to_string() + "[[scene.responses]]\nname = \"G\"\nkind = \"last\"\nof = [\"kinetic_energy\"]\n",
            "scene.responses[0].kind",
            "last",
            &["`integral`, `peak`, `final`"],
        ),
        // A plot of an output that is not a column of history.csv.
        (
            BASE.replace("quantities = [\"pin.angle\"]", "quantities = [\"pin.angle\"]\nplot = \"pin.rate\""),
            "scene.outputs.plot",
            "pin.rate",
            &["one of outputs.quantities (pin.angle)"],
        ),
        // Actuator segments with a gap, and with an overlap (written out
        // of order: the message names both by their written index).
        (
            actuator("{ lower = 0.5, upper = 2.0, value = 1.0 }, { lower = -1.0, upper = 0.4, value = 0.0 }"),
            "scene.forces[0].segments[0]",
            "(0.5, 2]",
            &["lower = 0.4", "forces[0].segments[1], (-1, 0.4]", "a gap"],
        ),
        (
            actuator("{ lower = -1.0, upper = 0.6, value = 0.0 }, { lower = 0.5, upper = 2.0, value = 1.0 }"),
            "scene.forces[0].segments[1]",
            "(0.5, 2]",
            &["lower = 0.6", "forces[0].segments[0], (-1, 0.6]", "an overlap"],
        ),
    ];
    for (text, key, value, expected) in cases {
        let InputError {
            file,
            key: k,
            value: v,
            expected: e,
            ..
        } = error_of("bad.toml", &text, load_scene);
        println!("{file}: {k} = {v}: expected {e}");
        assert_eq!(file, "bad.toml");
        assert_eq!(k, key, "value {v}");
        assert!(
            v.contains(value),
            "key {k}: value {v} should contain {value}"
        );
        for x in expected {
            assert!(
                e.contains(x),
                "key {k}: expected '{e}' should contain '{x}'"
            );
        }
    }
}

#[test]
fn effects_not_listed_are_not_built_or_evaluated() {
    let with = Study::parse("a.toml", BASE).unwrap();
    let without = Study::parse(
        "b.toml",
        &BASE.replace("effects = [\"gravity\"]", "effects = []"),
    )
    .unwrap();
    let (sys_a, sim_a) = simulate(&load_scene(&with).unwrap()).unwrap();
    let (sys_b, sim_b) = simulate(&load_scene(&without).unwrap()).unwrap();
    assert!(sys_a.counters.gravity.get() > 0);
    assert_eq!(sys_b.counters.gravity.get(), 0);
    // Gyroscopic terms only when `quadratic_velocity` is listed.
    assert_eq!(sys_a.counters.quadratic.get(), 0);
    assert!(!sys_a.model.quadratic_velocity);
    // A rigid scene never builds a flexible body.
    assert_eq!(sys_a.counters.flexible.get(), 0);
    assert!(sys_b.model.forces.is_empty());
    // Without gravity the pendulum stays at rest; with it, it swings.
    assert!(sim_b.rows.iter().all(|r| r[1].abs() < 1e-12));
    assert!(sim_a.rows.last().unwrap()[1].abs() > 0.1);
    // Actuator law and damping are separate effects.
    let sar = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/studies/sar_phase1_rigid.toml"
    ))
    .unwrap();
    let only_damping = Study::parse(
        "c.toml",
        // (the breakpoint sensitivity needs the law: leave it out)
        &sar.replace(
            "effects = [\"actuators\", \"damping\", \"quadratic_velocity\"]",
            "effects = [\"damping\"]",
        )
        .replace("sensitivities = [", "# sensitivities = ["),
    )
    .unwrap();
    let scene = load_scene(&only_damping).unwrap();
    match &scene.model.forces[..] {
        [plyscape::mbs::Force::Rotational {
            law: None, damping, ..
        }] => assert_eq!(*damping, 0.5),
        other => panic!("unexpected forces {other:?}"),
    }
}

#[test]
fn simulate_command_writes_history_stats_and_svg() {
    let tmp = crate::common::temp_dir("mbs-cli");
    let dir = tmp.path().to_path_buf();
    let study = dir.join("pendulum.toml");
    std::fs::write(
        &study,
        BASE.replace(
            "quantities = [\"pin.angle\"]",
            "quantities = [\"pin.angle\", \"pin.reaction\"]\nplot = \"pin.angle\"\n\
             [[scene.responses]]\nname = \"T_int\"\nkind = \"integral\"\nof = [\"kinetic_energy\"]\n\
             [[scene.responses]]\nname = \"T_max\"\nkind = \"peak\"\nof = [\"kinetic_energy\"]",
        ),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_plyscape"))
        .args([
            "simulate",
            study.to_str().unwrap(),
            "--out",
            dir.join("results").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("redundant"), "{stdout}");
    let res = dir.join("results/pendulum");
    let hist = std::fs::read_to_string(res.join("history.csv")).unwrap();
    assert!(
        hist.starts_with("t [s],pin.angle [rad],pin.force_x [N]"),
        "{hist}"
    );
    assert_eq!(hist.lines().count(), 7);
    let stats = std::fs::read_to_string(res.join("stats.csv")).unwrap();
    assert!(stats.contains("redundant_equations,0"), "{stats}");
    assert!(stats.starts_with("quantity,value,unit"), "{stats}");
    assert!(
        stats.contains("max_violation,") && stats.contains(",m or rad"),
        "{stats}"
    );
    assert!(res.join("pin.angle.svg").exists());
    // responses.csv names each response's unit.
    let resp = std::fs::read_to_string(res.join("responses.csv")).unwrap();
    let lines: Vec<&str> = resp.lines().collect();
    assert!(
        lines[0].starts_with("response,kind,value,unit,time [s]"),
        "{resp}"
    );
    assert!(
        lines[1].starts_with("T_int,integral,") && lines[1].contains(",J*s,"),
        "{resp}"
    );
    assert!(
        lines[2].starts_with("T_max,peak,") && lines[2].contains(",J,"),
        "{resp}"
    );
    // The manifest: the build's commit, the study text, start and end (UTC).
    let m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(res.join("manifest.json")).unwrap()).unwrap();
    assert_eq!(m["last_command"], "simulate");
    assert_eq!(m["git_commit"], plyscape::report::GIT_COMMIT);
    let sim = &m["commands"]["simulate"];
    for key in ["started", "ended"] {
        let t = sim[key].as_str().unwrap();
        assert!(
            t.len() == 20 && t.ends_with('Z') && t.as_bytes()[10] == b'T',
            "{t}"
        );
    }
    assert!(sim["started"].as_str() <= sim["ended"].as_str());
    assert!(sim["files"].to_string().contains("history.csv"));
    // A bad file gives exit code 2 (input error) and names the key.
    std::fs::write(&study, BASE.replace("mass = 1.0", "mass = 0.0")).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_plyscape"))
        .args([
            "simulate",
            study.to_str().unwrap(),
            "--out",
            dir.join("results").to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("scene.bodies[0].mass"));
}
