//! [`Pair`]: an explicit Runge–Kutta pair with a continuous extension,
//! for the explicit driver of `super::erk`. diffsol's tableaus hold at
//! most 8 stages and must end with the step's own solution (FSAL); a pair
//! of order 6 and up needs more (Verner's 6(5): 9 stages and one more for
//! its interpolant), so such pairs are stepped here.

/// An explicit Runge–Kutta pair: `s` stages advance the step, with
/// `y₁ = y₀ + h Σ bᵢ kᵢ` and the error estimate `h Σ eᵢ kᵢ` (`e = b − b̂`
/// with `b̂` the embedded solution's weights); the `extra` stages after
/// them serve the continuous extension only (computed when the dense
/// output is first asked for within a step). The dense output is
/// `y(t₀ + θh) = y₀ + h Σᵢ bᵢ(θ) kᵢ` over all `s + extra` stages, with
/// `bᵢ(θ) = Σₖ dense[i][k] θ^(k+1)`.
#[derive(Debug, Clone)]
pub(super) struct Pair {
    /// Stages of the step.
    pub(super) s: usize,
    /// `a[i]`: the coefficients of stages `0..i` in stage `i`, for all
    /// `s + extra` stages (`a[0]` empty).
    pub(super) a: Vec<Vec<f64>>,
    /// Nodes of all stages.
    pub(super) c: Vec<f64>,
    /// Weights of the solution (`s`).
    pub(super) b: Vec<f64>,
    /// Weights of the error estimate (`s`).
    pub(super) e: Vec<f64>,
    /// Order of the embedded solution (the error estimate is
    /// `O(h^(order+1))`; the step-size controller's exponent).
    pub(super) order: usize,
    /// Polynomial coefficients of the dense-output weights, per stage (all
    /// `s + extra`; stages without a row weigh nothing).
    pub(super) dense: Vec<Vec<f64>>,
    /// The last stage is evaluated at the step's end on its solution
    /// (`a[s−1] = b`, `c[s−1] = 1`): it is the next step's first stage.
    pub(super) fsal: bool,
}

impl Pair {
    /// Verner's "most efficient" 6(5) pair with 9 stages (FSAL) and his
    /// order-5 continuous extension with one more stage (`c = 1/2`).
    /// Coefficients: J. H. Verner's published table
    /// RKV65.IIIXb.Efficient.00000144617.081204 (his "Refuge for
    /// Runge–Kutta pairs", Simon Fraser University), the pair of
    /// J. H. Verner, "Numerically optimal Runge–Kutta pairs with
    /// interpolants", Numerical Algorithms 53 (2010) 383–396; written
    /// here to the table's digits (40 significant). The order conditions
    /// of the solution (6), of the embedded solution (5) and of the
    /// extension (5, for every θ) are checked in the tests.
    #[allow(clippy::excessive_precision)]
    pub(super) fn vern65() -> Pair {
        let c = vec![
            0.0,
            0.06,
            0.09593333333333333333333333333333333333333,
            0.1439,
            0.4973,
            0.9725,
            0.9995,
            1.0,
            1.0,
            0.5,
        ];
        let b = vec![
            0.3438957868357036009278820124728322386520e-1,
            0.0,
            0.0,
            0.2582624555633503404659558098586120858767,
            0.4209371189673537150642551514069801967032,
            4.405396469669310170148836816197095664891,
            -176.4831190242986576151740942499002125029,
            172.3641334014150730294022582711902413315,
            0.0,
        ];
        let b_hat = [
            0.4909967648382489730906854927971225836479e-1,
            0.0,
            0.0,
            0.2251112229516524153401395320539875329485,
            0.4694682253029562039431948525047387412553,
            0.8065792249988867707634161808995217981443,
            0.0,
            -0.6071194891777959797672951465256217122488,
            0.5686113944047569241147603178766138153594e-1,
        ];
        let a = vec![
            vec![],
            vec![0.06],
            vec![
                0.1923996296296296296296296296296296296296e-1,
                0.7669337037037037037037037037037037037037e-1,
            ],
            vec![0.35975e-1, 0.0, 0.107925],
            vec![
                1.318683415233148260919747276431735612861,
                0.0,
                -5.042058063628562225427761634715637693344,
                4.220674648395413964508014358283902080483,
            ],
            vec![
                -41.87259166432751461803757780644346812905,
                0.0,
                159.4325621631374917700365669070346830453,
                -122.1192135650100309202516203389242140663,
                5.531743066200053768252631238332999150076,
            ],
            vec![
                -54.43015693531650433250642051294142461271,
                0.0,
                207.0672513650184644273657173866509835987,
                -158.6108137845899991828742424365058599469,
                6.991816585950242321992597280791793907096,
                -0.1859723106220323397765171799549294623692e-1,
            ],
            vec![
                -54.66374178728197680241215648050386959351,
                0.0,
                207.9528062553893734515824816699834244238,
                -159.2889574744995071508959805871426654216,
                7.018743740796944434698170760964252490817,
                -0.1833878590504572306472782005141738268361e-1,
                -0.5119484997882099077875432497245168395840e-3,
            ],
            b[..8].to_vec(),
            vec![
                0.1652415901357280684383619367363197852645e-1,
                0.0,
                0.0,
                0.3053128187514178931377105638345583032476,
                0.2071200938201978848991082158995582390341,
                -1.293879140655123187129665774327355723229,
                57.11988411588149149650780257779402737914,
                -55.87979207510932290773937033203265749155,
                0.2483002829776601348057855515823731483430e-1,
            ],
        ];
        let dense = vern65_dense();
        let e = b.iter().zip(&b_hat).map(|(b, bh)| b - bh).collect();
        Pair {
            s: 9,
            a,
            c,
            b,
            e,
            order: 5,
            dense,
            fsal: true,
        }
    }

    /// The pair of a diffsol explicit tableau (its `d` as the error
    /// weights, its `beta` as the dense output; FSAL as diffsol requires
    /// of explicit tableaus), for checking the driver against diffsol's
    /// own stepping of the same tableau.
    #[cfg(test)]
    pub(super) fn of_tableau(t: &diffsol::Tableau<f64>) -> Pair {
        let s = t.s();
        let beta = t.beta_t().map(|m| m.transposed());
        Pair {
            s,
            a: (0..s)
                .map(|i| (0..i).map(|j| t.a(i, j)).collect())
                .collect(),
            c: t.c().as_slice().to_vec(),
            b: t.b().as_slice().to_vec(),
            e: t.d().as_slice().to_vec(),
            order: t.order(),
            dense: (0..s)
                .map(|i| match &beta {
                    Some(m) => (0..m.ncols()).map(|k| m[(i, k)]).collect(),
                    None => Vec::new(),
                })
                .collect(),
            fsal: true,
        }
    }

    /// All stages, the extension's included.
    pub(super) fn stages(&self) -> usize {
        self.c.len()
    }

    /// The dense-output weights `bᵢ(θ)` of every stage.
    pub(super) fn weights(&self, theta: f64) -> Vec<f64> {
        self.dense
            .iter()
            .map(|row| {
                let mut p = theta;
                let mut w = 0.0;
                for r in row {
                    w += r * p;
                    p *= theta;
                }
                w
            })
            .collect()
    }
}

/// The dense-output weights of [`Pair::vern65`]: per stage (the tenth is
/// the extension's own), the coefficients `dense[i][k]` of
/// `bᵢ(θ) = Σₖ dense[i][k] θ^(k+1)`, from the same table of Verner's as
/// the pair.
#[allow(clippy::excessive_precision)]
fn vern65_dense() -> Vec<Vec<f64>> {
    vec![
        vec![
            1.0,
            -5.308169607103576297743491917539437544903,
            10.18168044895868030520877351032733768603,
            -7.520036991611714828300683961994073691563,
            0.9340485368631160925057442706475838478288,
            0.7468671915770650884224462998058729264688,
        ],
        vec![],
        vec![],
        vec![
            0.0,
            6.272050253212501244827865529084399503479,
            -16.02618147467745958442607061022576892601,
            12.84435632451961742214954703737612797249,
            -1.148794504476759027536609501260874665600,
            -1.683168143014549714548776645115271798480,
        ],
        vec![
            0.0,
            6.876491702846304590450466371720363234704,
            -24.63576726084633318864583120149461053641,
            33.21078648379717088772133447477731248517,
            -17.49461528263643828092150992351036511970,
            2.464041475806649706459795429914280132942,
        ],
        vec![
            0.0,
            -35.54445171059960218765875699270358093032,
            165.7016170190242105108446269288474846144,
            -385.4635395491142731464726480659809841649,
            442.4324137015701845319394642134164121973,
            -182.7206429912112095385038492673822360516,
        ],
        vec![
            0.0,
            1918.654856698011449175045220651610014945,
            -9268.121508966042500195164712930044037430,
            20858.33702877255011893787944928058522511,
            -22645.82767158481047968149020787687967272,
            8960.474176055992754148556156624828257597,
        ],
        vec![
            0.0,
            -1883.069802132718312960582779305006646556,
            9101.025187200633795903395040749471730528,
            -20473.18855195953591834830509979123557878,
            22209.76555125653413900516974418122400018,
            -8782.168250963498630570274647563263264047,
        ],
        vec![
            0.0,
            0.1190247963512364356614756628348873476063,
            -0.1250269670503937512118264468821359362429,
            1.779956919394999075328101026471971070697,
            -4.660932123043762639666625363637083723091,
            2.886977374347920879888875121212361241030,
        ],
        vec![0.0, -8.0, 32.0, -40.0, 16.0, 0.0],
    ]
}
