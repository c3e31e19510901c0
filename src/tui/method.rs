//! Sharing the method area's rows between chart panels and text panels. Computed by hand rather than by
//! the layout solver, whose priorities would let a tall text squeeze the charts to nothing.

use ratatui::layout::Rect;

/// Rows each chart panel keeps before text panels may take more: borders, axis labels and a few rows
/// of plot.
const MIN_CHART_ROWS: u16 = 6;

/// Heights, top to bottom, of `charts` chart panels and then of one text panel per entry of
/// `text_rows` (the rows its text needs, borders included). Text panels get what they need where space
/// allows and a fair share of it where not; chart panels split the rest. Without charts, text panels
/// use the whole height: the last one takes any rows left over.
pub(crate) fn method_rows(charts: usize, text_rows: &[u16], height: u16) -> Vec<u16> {
    let reserved = u16::try_from(charts).unwrap_or(u16::MAX).saturating_mul(MIN_CHART_ROWS);
    let mut texts = fair_shares(text_rows, height.saturating_sub(reserved));
    let rest = height - texts.iter().sum::<u16>();
    if charts == 0 {
        if let Some(last) = texts.last_mut() {
            *last += rest;
        }
        return texts;
    }
    // `charts` is at most `rest` only on tall screens; the rows then go to the first charts.
    let rest = usize::from(rest);
    let mut rows: Vec<u16> = (0..charts).map(|i| (rest / charts + usize::from(i < rest % charts)) as u16).collect();
    rows.append(&mut texts);
    rows
}

/// Each demand met where `budget` allows; otherwise the smallest demands are met first and the budget
/// left is split evenly among the rest, so one long text cannot starve a short one.
fn fair_shares(demands: &[u16], budget: u16) -> Vec<u16> {
    let mut order: Vec<usize> = (0..demands.len()).collect();
    order.sort_by_key(|&i| demands[i]);
    let mut shares = vec![0; demands.len()];
    let mut left = budget;
    for (served, &i) in order.iter().enumerate() {
        let waiting = (demands.len() - served) as u16;
        shares[i] = demands[i].min(left / waiting);
        left -= shares[i];
    }
    shares
}

/// `area` cut into rows of the given heights, top to bottom.
pub(crate) fn stack(area: Rect, heights: &[u16]) -> Vec<Rect> {
    let mut y = area.y;
    heights
        .iter()
        .map(|&height| {
            let height = height.min(area.bottom().saturating_sub(y));
            let row = Rect { y, height, ..area };
            y += height;
            row
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_fits_and_charts_take_the_rest() {
        assert_eq!(method_rows(1, &[7, 3], 30), vec![20, 7, 3]);
        assert_eq!(method_rows(2, &[7], 30), vec![12, 11, 7]);
    }

    #[test]
    fn without_charts_the_last_text_panel_takes_the_slack() {
        assert_eq!(method_rows(0, &[7, 3], 30), vec![7, 23]);
        assert_eq!(method_rows(0, &[], 30), Vec::<u16>::new());
    }

    #[test]
    fn charts_keep_their_minimum_when_text_is_tall() {
        assert_eq!(method_rows(1, &[100], 30), vec![MIN_CHART_ROWS, 30 - MIN_CHART_ROWS]);
        assert_eq!(method_rows(2, &[100], 10), vec![5, 5, 0]);
    }

    #[test]
    fn short_texts_are_served_before_a_long_one() {
        assert_eq!(method_rows(0, &[100, 4, 5], 20), vec![11, 4, 5]);
        assert_eq!(method_rows(0, &[9, 9, 9], 20), vec![6, 7, 7]);
        assert_eq!(method_rows(1, &[100, 4], 20), vec![MIN_CHART_ROWS, 10, 4]);
    }

    #[test]
    fn rows_always_add_up_to_the_height() {
        for height in 0..40 {
            for charts in 0..4 {
                for texts in [&[][..], &[3], &[2, 50], &[9, 9, 9, 9]] {
                    let rows = method_rows(charts, texts, height);
                    assert_eq!(rows.len(), charts + texts.len());
                    if !rows.is_empty() {
                        assert_eq!(rows.iter().sum::<u16>(), height, "{charts} charts, {texts:?}, {height} rows");
                    }
                }
            }
        }
    }

    #[test]
    fn stack_cuts_top_to_bottom_and_clips() {
        let area = Rect::new(2, 3, 10, 8);
        let rows = stack(area, &[3, 4, 5]);
        assert_eq!(rows, vec![Rect::new(2, 3, 10, 3), Rect::new(2, 6, 10, 4), Rect::new(2, 10, 10, 1)]);
    }
}
