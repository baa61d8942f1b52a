use super::*;
use crate::optimize::indicators::igd;
use crate::optimize::mo_testproblems::zdt1;
use crate::optimize::multiobjective::MultiEvaluation;
use crate::optimize::Variable;

fn ind(f: &[f64], violation: f64) -> Individual {
    Individual {
        x: vec![],
        f: f.to_vec(),
        g: vec![],
        violation,
    }
}

#[test]
fn fronts_by_hand() {
    // (1,4), (2,2), (4,1) are mutually non-dominated; (3,3) is dominated
    // by (2,2) only; (4,4) by everyone above; an infeasible point comes
    // after every feasible one, whatever its objectives.
    let pop = vec![
        ind(&[3.0, 3.0], 0.0),
        ind(&[1.0, 4.0], 0.0),
        ind(&[0.0, 0.0], 0.5),
        ind(&[2.0, 2.0], 0.0),
        ind(&[4.0, 4.0], 0.0),
        ind(&[4.0, 1.0], 0.0),
        ind(&[0.0, 0.0], 0.2),
    ];
    let fronts = fast_non_dominated_sort(&pop, 0.0);
    assert_eq!(
        fronts,
        vec![vec![1, 3, 5], vec![0], vec![4], vec![6], vec![2]]
    );
    // With a tolerance of 0.3 the point violated by 0.2 is feasible and
    // dominates everything.
    assert_eq!(fast_non_dominated_sort(&pop, 0.3)[0], vec![6]);
}

#[test]
fn crowding_distance_by_hand() {
    // Front (0,4), (1,2), (3,1), (4,0): ranges 4 and 4. Interior (1,2):
    // (3 − 0)/4 + (4 − 1)/4 = 1.5; (3,1): (4 − 1)/4 + (2 − 0)/4 = 1.25.
    let pop = vec![
        ind(&[3.0, 1.0], 0.0),
        ind(&[0.0, 4.0], 0.0),
        ind(&[4.0, 0.0], 0.0),
        ind(&[1.0, 2.0], 0.0),
    ];
    let d = crowding_distance(&pop, &[0, 1, 2, 3]);
    assert_eq!(d[0], 1.25);
    assert_eq!(d[3], 1.5);
    assert!(d[1].is_infinite() && d[2].is_infinite());
}

#[test]
fn operators_stay_in_the_box_and_spread_around_the_parents() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut mean = 0.0;
    for _ in 0..2000 {
        let u = rng.random::<f64>();
        let (a, b) = sbx_pair(0.2, 0.6, (0.0, 1.0), 20.0, u);
        assert!((0.0..=1.0).contains(&a) && (0.0..=1.0).contains(&b));
        assert!(a <= b);
        // SBX keeps the parents' mean away from the bounds.
        mean += 0.5 * (a + b) / 2000.0;
        let m = poly_mutation(0.99, (0.0, 1.0), 20.0, rng.random::<f64>());
        assert!((0.0..=1.0).contains(&m));
    }
    assert!((mean - 0.4).abs() < 1e-2, "{mean}");
    // u = 0.5 gives the parents back (β_q = 1), and mutation none.
    let (a, b) = sbx_pair(0.2, 0.6, (-10.0, 10.0), 20.0, 0.5);
    assert!((a - 0.2).abs() < 1e-3 && (b - 0.6).abs() < 1e-3, "{a} {b}");
    assert_eq!(poly_mutation(0.3, (0.0, 1.0), 20.0, 0.5), 0.3);
}

#[test]
fn zdt1_is_solved_and_a_seed_repeats_the_run() {
    let p = zdt1();
    let o = Nsga2Options {
        max_evaluations: 10_000,
        seed: 7,
        ..Nsga2Options::default()
    };
    let a = minimize(&p, &o).unwrap();
    let b = minimize(&p, &o).unwrap();
    assert_eq!(a.evaluations, 10_000);
    assert_eq!(a.generations, 99);
    let fa: Vec<Vec<f64>> = a.front.iter().map(|i| i.f.clone()).collect();
    let fb: Vec<Vec<f64>> = b.front.iter().map(|i| i.f.clone()).collect();
    assert_eq!(fa, fb);
    let v = igd(&fa, &p.front()).unwrap();
    // At 10 000 evaluations NSGA-II is close to ZDT1's front, not on it.
    assert!(v < 0.05, "IGD {v}");
}

/// min (x, y) subject to x + y >= 1 on [0, 1]²: the front is the segment
/// x + y = 1.
struct Segment(Vec<Variable>);

impl MultiProblem for Segment {
    fn variables(&self) -> &[Variable] {
        &self.0
    }
    fn objective_names(&self) -> Vec<String> {
        vec!["x".into(), "y".into()]
    }
    fn n_constraints(&self) -> usize {
        1
    }
    fn evaluate(&self, x: &[f64], _gradients: bool) -> crate::error::Result<MultiEvaluation> {
        Ok(MultiEvaluation::smooth(
            (x.to_vec(), vec![1.0 - x[0] - x[1]]),
            None,
            None,
        ))
    }
    fn name(&self) -> &str {
        "segment"
    }
}

#[test]
fn constraint_domination_keeps_the_front_feasible() {
    let p = Segment(vec![
        Variable::bounded("x", 0.0, 1.0).unwrap(),
        Variable::bounded("y", 0.0, 1.0).unwrap(),
    ]);
    let o = Nsga2Options {
        population: 40,
        max_evaluations: 4000,
        ..Nsga2Options::default()
    };
    let r = minimize(&p, &o).unwrap();
    assert!(r.front.len() >= 20, "{}", r.front.len());
    let mut mean = 0.0;
    for i in &r.front {
        assert!(i.g[0] <= 0.0);
        assert!(i.f[0] + i.f[1] < 1.05, "{:?}", i.f);
        mean += (i.f[0] + i.f[1]) / r.front.len() as f64;
    }
    assert!(mean < 1.02, "{mean}");
    let bad = Nsga2Options { population: 5, ..o };
    assert!(minimize(&p, &bad).is_err());
}
