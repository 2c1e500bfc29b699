//! The scene parser never panics: arbitrary text, and scenes assembled from the real fields with
//! hostile values. Scenes that parse are planned and rendered tiny by both renderers, which may
//! refuse them but must not panic (proptest, a bounded number of cases in the normal test run).

use cube5_model::render::{render_pipeline, render_reference};
use cube5_model::scene::{Plan, Scene};
use proptest::prelude::*;

fn value() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("nan".to_string()),
        Just("inf".to_string()),
        Just("-inf".to_string()),
        Just("0".to_string()),
        Just("-1".to_string()),
        Just("1e308".to_string()),
        Just("\"\"".to_string()),
        Just("[]".to_string()),
        Just("[0, 0, 0]".to_string()),
        Just("[nan, 1, 2]".to_string()),
        (-2000i64..2000).prop_map(|v| v.to_string()),
        (-2.0f64..2.0).prop_map(|v| format!("{v:?}")),
        "[a-z-]{0,12}".prop_map(|s| format!("\"{s}\"")),
        Just("\"mip\"".to_string()),
        Just("\"sheared\"".to_string()),
        Just("\"perspective\"".to_string()),
        Just(
            "[{ density = 0.5, rgba = [1, 1, 1, 1] }, { density = 0.1, rgba = [0, 0, 0, 0] }]"
                .to_string()
        ),
    ]
}

fn field() -> impl Strategy<Value = (&'static str, &'static str)> {
    prop::sample::select(vec![
        ("volume", "phantom"),
        ("volume", "size"),
        ("volume", "bits"),
        ("volume", "spacing"),
        ("volume", "dims"),
        ("view", "azimuth"),
        ("view", "elevation"),
        ("view", "direction"),
        ("view", "projection"),
        ("view", "fov"),
        ("view", "zoom"),
        ("image", "width"),
        ("image", "height"),
        ("render", "mode"),
        ("render", "step"),
        ("render", "early_termination"),
        ("render", "threshold"),
        ("transfer", "preset"),
        ("transfer", "points"),
        ("shading", "ambient"),
        ("shading", "shininess"),
        ("quality", "voxel_bits"),
        ("quality", "weight_bits"),
        ("quality", "frac_bits"),
        ("quality", "colour_bits"),
        ("quality", "samples_per_slice"),
        ("quality", "supersampling"),
        ("quality", "interpolation"),
        ("quality", "gradient"),
        ("run", "target"),
        ("run", "renderer"),
    ])
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(128))]

    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,300}") {
        let _ = Scene::parse(&text, "fuzz.toml");
    }

    #[test]
    fn hostile_values_never_panic(fields in proptest::collection::vec((field(), value()), 0..6)) {
        let mut tables: std::collections::BTreeMap<&str, Vec<String>> = Default::default();
        for ((table, key), v) in fields {
            tables.entry(table).or_default().push(format!("{key} = {v}"));
        }
        let mut text = String::new();
        for (table, lines) in tables {
            text.push_str(&format!("[{table}]\n"));
            // Duplicate keys are a TOML error: keep the first of each.
            let mut seen = std::collections::BTreeSet::new();
            for l in lines {
                if seen.insert(l.split(' ').next().unwrap().to_string()) {
                    text.push_str(&l);
                    text.push('\n');
                }
            }
        }
        if let Ok(mut scene) = Scene::parse(&text, "fuzz.toml") {
            // Keep the work tiny: a small phantom and image.
            scene.volume.size = scene.volume.size.min(12);
            scene.image.width = scene.image.width.min(8);
            scene.image.height = scene.image.height.min(8);
            scene.quality.supersampling = scene.quality.supersampling.min(2);
            scene.quality.samples_per_slice = scene.quality.samples_per_slice.min(2);
            if scene.render.step < 0.25 {
                scene.render.step = 0.25;
            }
            if let Ok(vol) = scene.build_volume() {
                let _ = Plan::new(&scene, &vol);
                let (tf, params) = (scene.transfer_function(), scene.render_params());
                let _ = render_reference(&vol, &tf, &params);
                let _ = render_pipeline(&vol, &tf, &params, &scene.quality());
            }
        }
    }
}
