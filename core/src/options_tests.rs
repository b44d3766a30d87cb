//! The option tables' own tests (`options.rs`).

use super::*;
use crate::bvh::Param;

fn check<T: Choice + std::fmt::Debug>() {
    for (i, n) in T::TABLE.iter().enumerate() {
        assert_eq!(T::from_name(n.name), Some(n.value));
        assert!(T::TABLE[..i].iter().all(|m| m.name != n.name && m.value != n.value), "{:?} twice", n.value);
        assert!(!n.help.is_empty() && !n.label.is_empty());
        assert!(n.name.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-'), "{}", n.name);
    }
    assert_eq!(T::from_name("no such thing"), None);
}

#[test]
fn every_choice_is_named_once_and_found_by_its_name() {
    check::<Strategy>();
    check::<Layout>();
    check::<TraversalOrder>();
    check::<TriangleTest>();
    check::<View>();
    check::<ColorMap>();
    check::<UpAxis>();
    check::<Preset>();
    check::<PairView>();
    assert_eq!(Strategy::ALL.len(), STRATEGIES.len());
    assert_eq!(View::ALL[2], View::Visits);
}

#[test]
fn the_handout_help_states_the_leaf_size_the_preset_uses() {
    let leaf = format!("max leaf size {}", Preset::HANDOUT_MAX_LEAF_SIZE);
    assert!(Preset::Handout.help().contains(&leaf));
}

#[test]
fn every_build_parameter_is_named_once_and_parses_its_default() {
    for (i, o) in BUILD_PARAMS.iter().enumerate() {
        assert!(BUILD_PARAMS[..i].iter().all(|p| p.param != o.param && p.name != o.name && p.key != o.key));
        assert_eq!(o.key, o.name.replace('-', "_"), "{}: the key is the name in snake case", o.name);
        assert_eq!(o.param.option().name, o.name);
        let d = o.limits().default_value();
        assert_eq!(o.parse(&d.to_string()), Ok(d));
        assert_eq!(o.from_json(&ParamOption::to_json(d)), Ok(d));
        assert!(o.help_line().contains(&o.limits().range_text()));
    }
    assert_eq!(BUILD_PARAMS.len(), Param::ALL.len());
    assert!(Param::MaxLeafSize.option().parse("0").is_err() && Param::MaxLeafSize.option().parse("256").is_err());
    assert!(Param::TraversalCost.option().parse("nan").is_err());
}
